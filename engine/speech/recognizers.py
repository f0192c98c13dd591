"""Which recognizers are installed, and the robot's default.

"moonshine" is the default: Moonshine Base English (:mod:`engine.speech.moonshine`) hears
every utterance in about a seventh of Whisper's time; when none of the dialogs' phrases
is in what it wrote (a word it got wrong, a sentence no rule means), it hears the
utterance again allowed to write only those phrases, and keeps the phrase when the audio
bears it out (:mod:`engine.speech.phrase_search`, a tenth of a second). It replaced
Whisper's second opinion (0.8 s), and answers more of bench/bench_speech.py's clips right.
"whisper" is Whisper tiny.en alone, prompted with the phrases, and the fallback where
Moonshine's package is not installed (its wheels are x86_64 only). A profile chooses
with ``recognizer:``; ``vest hear`` and ``vest dialogs check`` with ``--recognizer``.
"""

from __future__ import annotations

from engine.speech.recognizer import Recognizer, RecognizerError
from engine.speech.settings import RECOGNIZER_NAMES

DEFAULT_RECOGNIZER = "moonshine"


def load_recognizer(name: str) -> Recognizer:
    """The recognizer called ``name``; RecognizerError saying why it cannot hear."""
    if name == "moonshine":
        from engine.speech.moonshine import MoonshineRecognizer

        return MoonshineRecognizer()
    if name == "whisper":
        from engine.speech.recognizer import WhisperRecognizer

        return WhisperRecognizer()
    raise RecognizerError(f"no recognizer {name!r}; recognizers: {', '.join(RECOGNIZER_NAMES)}")


def default_recognizer(name: str | None = None) -> tuple[Recognizer, str | None]:
    """The recognizer ``name`` (default moonshine), or the other one with why the wanted
    one cannot hear; RecognizerError when neither can."""
    wanted = name or DEFAULT_RECOGNIZER
    try:
        return load_recognizer(wanted), None
    except RecognizerError as error:
        other = next(n for n in RECOGNIZER_NAMES if n != wanted)
        try:
            return load_recognizer(other), f"{error}; hearing with {other}"
        except RecognizerError as second:
            raise RecognizerError(f"{error}; and {second}") from None
