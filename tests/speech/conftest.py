"""Real speech models for the speech tests: loaded once per session (they take a second)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import load_dialog
from engine.dialogs.model import Dialog, FollowUp
from engine.media.audio import Audio, with_noise
from engine.speech.recognizer import Recognizer, WhisperRecognizer
from engine.speech.recognizers import DEFAULT_RECOGNIZER, load_recognizer
from engine.speech.vad import SileroVad
from engine.speech.voice_models import load_voice
from engine.speech.voices import NeuralVoice, Voice, steady_voice

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def default_dialog() -> Dialog:
    return load_dialog(ROOT / "dialogs" / "default.yaml", default_catalogue())


@pytest.fixture(scope="session")
def pets_answers(default_dialog: Dialog) -> FollowUp:
    """The answers the default dialog listens for after "Do you have a pet?"."""
    pets = next(rule for rule in default_dialog.rules if rule.id == "pets")
    assert pets.follow_up is not None
    return pets.follow_up


@pytest.fixture(scope="session")
def recognizer(default_dialog: Dialog) -> Recognizer:
    """The robot's default recognizer, listening for the default dialog."""
    recognizer = load_recognizer(DEFAULT_RECOGNIZER)
    recognizer.listen_for(default_dialog.phrases)
    return recognizer


@pytest.fixture(scope="session")
def whisper(default_dialog: Dialog) -> WhisperRecognizer:
    """Whisper tiny.en, the recognizer a profile may choose instead."""
    recognizer = WhisperRecognizer()
    recognizer.listen_for(default_dialog.phrases)
    return recognizer


@pytest.fixture(scope="session")
def vad() -> SileroVad:
    return SileroVad()


@pytest.fixture(scope="session")
def voices() -> dict[str, Voice]:
    joe = load_voice("joe")
    assert isinstance(joe, NeuralVoice)
    return {
        "hibari": steady_voice(load_voice("hibari")),
        "joe": joe.steady(),
        "espeak": load_voice("espeak"),
    }


@pytest.fixture(scope="session")
def spoken(voices: dict[str, Voice]) -> Callable[..., Audio]:
    """``spoken(text, voice="joe", speed=1.0, snr_db=None)``: a person saying ``text``
    with quiet before and after, at half of full scale, with white noise when asked."""

    def speak(
        text: str, voice: str = "joe", speed: float = 1.0, snr_db: float | None = None
    ) -> Audio:
        speech = voices[voice].synthesize(text, speed=speed)
        pad = Audio.silence(0.4, speech.rate_hz)
        audio = pad.then(speech).then(pad)
        if snr_db is not None:
            audio = with_noise(audio, snr_db, seed=len(text))
        return audio.scaled(0.5)

    return speak
