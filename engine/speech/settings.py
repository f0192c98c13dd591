"""The speech settings a profile may give: the voice, how fast it speaks, the recognizer
that hears, and whom it hears."""

from __future__ import annotations

from typing import Any

VOICE_NAMES = ("hibari", "joe", "espeak")
RECOGNIZER_NAMES = ("moonshine", "whisper")
HEARING_NAMES = ("adults", "children")
SPEECH_PROFILE_PARAMS = ("voice", "speech_rate", "recognizer", "hearing")
"""Profile parameters the speech itself reads (no tree needs to declare them):
``voice`` (hibari, joe or espeak), ``speech_rate`` (1 natural, 0.5..2), ``recognizer``
(moonshine or whisper) and ``hearing`` (adults, the default, or children: longer pauses
within a sentence, and phrases as children say them, :mod:`engine.speech.children`)."""


def check_speech_params(params: dict[str, Any]) -> list[tuple[str, str, str]]:
    """(name, message, hint) for each bad speech setting among a profile's ``params``
    (plain values by name)."""
    problems: list[tuple[str, str, str]] = []
    voice = params.get("voice")
    if voice is not None and voice not in VOICE_NAMES:
        problems.append(("voice", f"no voice {voice!r}", "voices: " + ", ".join(VOICE_NAMES)))
    recognizer = params.get("recognizer")
    if recognizer is not None and recognizer not in RECOGNIZER_NAMES:
        problems.append(
            (
                "recognizer",
                f"no recognizer {recognizer!r}",
                "recognizers: " + ", ".join(RECOGNIZER_NAMES),
            )
        )
    hearing = params.get("hearing")
    if hearing is not None and hearing not in HEARING_NAMES:
        problems.append(
            ("hearing", f"no hearing {hearing!r}", "hearing: " + " or ".join(HEARING_NAMES))
        )
    rate = params.get("speech_rate")
    if rate is not None and (
        isinstance(rate, bool) or not isinstance(rate, int | float) or not 0.5 <= rate <= 2.0
    ):
        problems.append(
            ("speech_rate", f"speech_rate must be 0.5..2, got {rate!r}", "1 is natural")
        )
    return problems
