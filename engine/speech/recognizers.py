"""Which recognizers are installed, and the robot's default.

"moonshine" is the default: Moonshine Base English (:mod:`engine.speech.moonshine`) hears
every utterance first, in about a seventh of Whisper's time; when none of the dialogs'
phrases is in what it heard (a word it got wrong, a sentence no rule means), Whisper
tiny.en, prompted with those phrases, hears the utterance again and its transcript is
the one told (:class:`SecondOpinion`). Most answers come at Moonshine's speed; the
phrases Moonshine alone misses are still understood (bench/bench_speech.py measures
both). "whisper" is Whisper alone, and the fallback where Moonshine's package is not
installed (its wheels are x86_64 only). A profile chooses with ``recognizer:``;
``vest hear`` and ``vest dialogs check`` with ``--recognizer``.
"""

from __future__ import annotations

from collections.abc import Iterable

from engine.dialogs.words import is_function_word, same_word, words
from engine.media.audio import Audio
from engine.speech.recognizer import Recognizer, RecognizerError, Transcript
from engine.speech.settings import RECOGNIZER_NAMES

DEFAULT_RECOGNIZER = "moonshine"


def holds_a_phrase(text: str, phrases: list[tuple[str, ...]]) -> bool:
    """Whether ``text`` holds every meaning word of one of ``phrases`` (each as its
    :func:`~engine.dialogs.words.words`), or all the words of a phrase of function words
    only ("how are you"), and no meaning word that none of them has (a word misheard
    beside the phrase's: "what is your favorite mid-colour")."""
    heard = words(text)
    known = {word for phrase in phrases for word in phrase}
    if any(word not in known and not is_function_word(word) for word in heard):
        return False
    for phrase in phrases:
        meaning = [word for word in phrase if not is_function_word(word)]
        if not meaning:
            if tuple(heard) == phrase:
                return True
        elif all(any(same_word(h, word) for h in heard) for word in meaning):
            return True
    return False


class SecondOpinion:
    """A fast recognizer whose transcripts are kept when they hold one of the phrases
    listened for; otherwise a careful one hears the utterance again."""

    def __init__(self, fast: Recognizer, careful: Recognizer) -> None:
        self.fast = fast
        self.careful = careful
        self.name = f"{getattr(fast, 'name', 'fast')}, then {getattr(careful, 'name', 'careful')}"
        self.phrases: list[tuple[str, ...]] = []
        self.second_opinions = 0
        """Utterances the careful recognizer heard again (for the benchmarks)."""

    def listen_for(self, phrases: Iterable[str]) -> None:
        listened = list(phrases)
        self.phrases = [words(phrase) for phrase in listened]
        self.fast.listen_for(listened)
        self.careful.listen_for(listened)

    def transcribe(self, audio: Audio) -> Transcript:
        heard = self.fast.transcribe(audio)
        if heard.text and holds_a_phrase(heard.text, self.phrases):
            return heard
        self.second_opinions += 1
        return self.careful.transcribe(audio)


def load_recognizer(name: str) -> Recognizer:
    """The recognizer called ``name``; RecognizerError saying why it cannot hear."""
    from engine.speech.recognizer import WhisperRecognizer

    if name == "moonshine":
        from engine.speech.moonshine import MoonshineRecognizer

        return SecondOpinion(MoonshineRecognizer(), WhisperRecognizer())
    if name == "whisper":
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
