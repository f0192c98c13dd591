"""The speech settings a profile may give: the voice and how fast it speaks."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from engine.loader.substitution import Profile

from engine.files.yaml_values import plain

VOICE_NAMES = ("joe", "espeak")
SPEECH_PROFILE_PARAMS = ("voice", "speech_rate")
"""Profile parameters the speech itself reads (no tree needs to declare them):
``voice`` (joe or espeak) and ``speech_rate`` (1 natural, 0.5..2)."""


def check_speech_params(params: dict[str, Any]) -> list[tuple[str, str, str]]:
    """(name, message, hint) for each bad speech setting among a profile's ``params``
    (plain values by name)."""
    problems: list[tuple[str, str, str]] = []
    voice = params.get("voice")
    if voice is not None and voice not in VOICE_NAMES:
        problems.append(("voice", f"no voice {voice!r}", "voices: " + ", ".join(VOICE_NAMES)))
    rate = params.get("speech_rate")
    if rate is not None and (
        isinstance(rate, bool) or not isinstance(rate, int | float) or not 0.5 <= rate <= 2.0
    ):
        problems.append(
            ("speech_rate", f"speech_rate must be 0.5..2, got {rate!r}", "1 is natural")
        )
    return problems


def speech_settings(profile: Profile | None) -> dict[str, Any]:
    """The voice and speed a profile asks for, as :func:`build_speech` keywords."""
    if profile is None:
        return {}
    values = {
        name: plain(profile.params[name].value)
        for name in SPEECH_PROFILE_PARAMS
        if name in profile.params
    }
    settings: dict[str, Any] = {}
    if "voice" in values:
        settings["voice_name"] = str(values["voice"])
    if "speech_rate" in values:
        settings["speed"] = float(values["speech_rate"])
    return settings
