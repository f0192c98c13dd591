"""The speech settings a profile may give: the voice and how fast it speaks."""

from __future__ import annotations

from typing import Any

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
