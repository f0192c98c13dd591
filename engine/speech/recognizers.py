"""Which recognizers are installed, and the robot's default.

"moonshine" is the default: Moonshine Base English (:mod:`engine.speech.moonshine`) hears
every utterance in about a seventh of Whisper's time; when none of the dialogs' phrases
is in what it wrote (a word it got wrong, a sentence no rule means), it hears the
utterance again allowed to write only those phrases, and keeps the phrase when the audio
bears it out (:mod:`engine.speech.phrase_search`, a tenth of a second). A phrase it is not
sure of (a short sound forced into "yes", a long mumble into a short phrase) is heard again
by Whisper tiny.en, prompted with the phrases, whose transcript counts where the two
agree (:class:`SecondOpinion`): about one utterance in twenty on bench/bench_speech.py's
clips, where Whisper once heard every utterance Moonshine's words did not hold.
"whisper" is Whisper tiny.en alone, prompted with the phrases, and the fallback where
Moonshine's package is not installed (its wheels are x86_64 only). A profile chooses
with ``recognizer:``; ``vest hear`` and ``vest dialogs check`` with ``--recognizer``.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Protocol

from engine.dialogs.words import same_word, words
from engine.media.audio import Audio
from engine.speech.recognizer import Abandon, Recognizer, RecognizerError, Transcript
from engine.speech.settings import RECOGNIZER_NAMES

DEFAULT_RECOGNIZER = "moonshine"


class FindsPhrases(Recognizer, Protocol):
    """A recognizer that can tell whether an utterance bears out given phrases."""

    def finds(self, audio: Audio, phrases: Iterable[str]) -> bool:
        """Whether ``audio`` bears out one of ``phrases``."""
        ...


class NoWords:
    """A recognizer that hears no words: for listening only to where speech begins and
    ends (how a robot hears its own voice, benchmarks of barge-in)."""

    name = "none"

    def listen_for(self, phrases: Iterable[str]) -> None:
        """Nothing is listened for."""

    def transcribe(self, audio: Audio, *, abandon: Abandon | None = None) -> Transcript:
        return Transcript("")


class SecondOpinion:
    """A fast recognizer, and a careful one that hears again the utterances whose phrase
    the fast one found but is not sure of (:attr:`Transcript.unconfirmed`). The careful
    transcript is the one told when the two agree: it says that phrase too (its words in
    order, as the matcher reads them: "Yeah, I have a puppy?" says "yeah"), or the fast
    recognizer finds in the audio a phrase the careful one wrote ("Yeah?" where it had
    "yes"). Otherwise they disagree and the utterance is heard as nothing (the robot says it
    did not understand): a "huh" that Moonshine finds nearest to "yeah" and prompted
    Whisper writes as "Hello?" is neither. Where the careful recognizer doubted what it
    wrote (Whisper checks a transcript of function words only, like "who are you",
    against a decoding without the phrases), three words or more that say exactly the
    fast one's phrase count: two recognizers that each wrote them."""

    def __init__(self, fast: FindsPhrases, careful: Recognizer) -> None:
        self.fast = fast
        self.careful = careful
        fast_name, careful_name = getattr(fast, "name", "fast"), getattr(careful, "name", "careful")
        self.name = f"{fast_name}, {careful_name} when unsure"
        self.second_opinions = 0
        """Utterances the careful recognizer heard again (for the benchmarks)."""
        self.phrases: list[str] = []

    def listen_for(self, phrases: Iterable[str]) -> None:
        self.phrases = list(phrases)
        self.fast.listen_for(self.phrases)
        self.careful.listen_for(self.phrases)

    def transcribe(self, audio: Audio, *, abandon: Abandon | None = None) -> Transcript:
        heard = self.fast.transcribe(audio, abandon=abandon)
        if not heard.unconfirmed or (abandon is not None and abandon()):
            return heard
        self.second_opinions += 1
        careful = self.careful.transcribe(audio, abandon=abandon)
        if says(careful.text, heard.unconfirmed):
            return careful
        doubted = " ".join(word.text for word in careful.words)
        if (
            not careful.text
            and len(words(heard.unconfirmed)) >= 3
            and words(doubted) == words(heard.unconfirmed)
        ):
            return Transcript(doubted, careful.words, careful.no_speech, careful.log_prob)
        written = [phrase for phrase in self.phrases if says(careful.text, phrase)]
        if written and self.fast.finds(audio, written):
            return careful
        return Transcript("", careful.words, careful.no_speech, careful.log_prob)


def says(text: str, phrase: str) -> bool:
    """Whether ``text`` holds the words of ``phrase`` in order (others between and around
    them), as the matcher reads words: "Yeah, I have a puppy?" says "yeah"."""
    wanted = list(words(phrase))
    for word in words(text):
        if wanted and same_word(word, wanted[0]):
            wanted.pop(0)
    return bool(words(phrase)) and not wanted


def load_recognizer(name: str, *, children: bool = False) -> Recognizer:
    """The recognizer called ``name``; RecognizerError saying why it cannot hear.
    ``children``: Moonshine's closed listening also keeps phrases as children say them
    (:mod:`engine.speech.children`; Whisper's hearing is the same for all)."""
    from engine.speech.recognizer import WhisperRecognizer

    if name == "moonshine":
        from engine.speech.moonshine import MoonshineRecognizer

        return SecondOpinion(MoonshineRecognizer(children=children), WhisperRecognizer())
    if name == "whisper":
        return WhisperRecognizer()
    raise RecognizerError(f"no recognizer {name!r}; recognizers: {', '.join(RECOGNIZER_NAMES)}")


def default_recognizer(
    name: str | None = None, *, children: bool = False
) -> tuple[Recognizer, str | None]:
    """The recognizer ``name`` (default moonshine; ``children`` as for
    :func:`load_recognizer`), or the other one with why the wanted one cannot hear;
    RecognizerError when neither can."""
    wanted = name or DEFAULT_RECOGNIZER
    try:
        return load_recognizer(wanted, children=children), None
    except RecognizerError as error:
        other = next(n for n in RECOGNIZER_NAMES if n != wanted)
        try:
            return load_recognizer(other, children=children), f"{error}; hearing with {other}"
        except RecognizerError as second:
            raise RecognizerError(f"{error}; and {second}") from None
