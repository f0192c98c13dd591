"""The robot's voices: a neural voice (Piper's ONNX format, run here with ONNX Runtime)
and espeak-ng, the robotic fallback that needs no model.

Both speak one sentence at a time (:func:`sentences` splits a reply), so the speaker can
play the first while the next is synthesized. Neither imports GPL code: the neural voice
is phonemized by the ``espeak-ng`` program, run as a separate process, and the model is
run by ONNX Runtime (MIT). ``speed`` is 1 for the voice's natural rate, 2 for twice as fast.
"""

from __future__ import annotations

import copy
import json
import re
import shutil
import subprocess
import unicodedata
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from engine.errors import DeviceError
from engine.media.audio import Audio

ESPEAK = "espeak-ng"
_SENTENCE_END = re.compile(r"(?<=[.!?])\s+")
_CLAUSE_MARKS = re.compile(r"[,;:]")
MAX_SENTENCE_CHARS = 400
"""A longer run of text without a full stop is cut at a word near this many characters."""


class VoiceError(DeviceError):
    """A voice that cannot speak (model missing, espeak-ng missing or failing), in words."""


class Voice(Protocol):
    name: str

    def synthesize(self, sentence: str, *, speed: float = 1.0) -> Audio:
        """One sentence as audio; VoiceError when the voice cannot speak."""
        ...


def sentences(text: str) -> list[str]:
    """``text`` cut into sentences (and overlong sentences at a word boundary)."""
    found: list[str] = []
    for sentence in _SENTENCE_END.split(text.strip()):
        while len(sentence) > MAX_SENTENCE_CHARS:
            cut = sentence.rfind(" ", 0, MAX_SENTENCE_CHARS)
            cut = cut if cut > 0 else MAX_SENTENCE_CHARS
            found.append(sentence[:cut].strip())
            sentence = sentence[cut:]
        if sentence.strip():
            found.append(sentence.strip())
    return found


def _espeak(args: list[str], text: str) -> bytes:
    if shutil.which(ESPEAK) is None:
        raise VoiceError("espeak-ng is not installed (scripts/setup installs it)")
    try:
        done = subprocess.run(
            [ESPEAK, *args, "--", text], capture_output=True, timeout=30, check=False
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        raise VoiceError(f"espeak-ng failed: {error}") from None
    if done.returncode != 0:
        why = done.stderr.decode(errors="replace").strip() or f"exit {done.returncode}"
        raise VoiceError(f"espeak-ng failed: {why}")
    return done.stdout


class EspeakVoice:
    """espeak-ng's formant voice: robotic, but always there and instant."""

    def __init__(self, language: str = "en-us", words_per_minute: int = 165) -> None:
        self.name = "espeak"
        self.language = language
        self.words_per_minute = words_per_minute

    def synthesize(self, sentence: str, *, speed: float = 1.0) -> Audio:
        wpm = max(80, min(450, round(self.words_per_minute * speed)))
        data = _espeak(["--stdout", "-v", self.language, "-s", str(wpm)], sentence)
        return _streamed_wav(data)


def _streamed_wav(data: bytes) -> Audio:
    """espeak-ng's WAV on a pipe: its header cannot know the length, so the samples are
    everything after the ``data`` chunk's header (16-bit mono)."""
    at = data.find(b"data", 12)
    if not data.startswith(b"RIFF") or at < 0:
        raise VoiceError("espeak-ng wrote no WAV audio")
    rate_hz = int.from_bytes(data[24:28], "little")
    return Audio.from_pcm16(data[at + 8 :], rate_hz)


@dataclass(frozen=True)
class VoiceModel:
    """A neural voice's files: the ONNX model and its JSON config beside it."""

    name: str
    model: Path
    config: Path


class NeuralVoice:
    """A Piper-format VITS voice: text -> espeak-ng IPA phonemes -> ids -> ONNX -> audio."""

    def __init__(self, files: VoiceModel, *, use_cuda: bool = False, threads: int = 1) -> None:
        import onnxruntime

        try:
            config: dict[str, Any] = json.loads(files.config.read_text(encoding="utf-8"))
            self.rate_hz = int(config["audio"]["sample_rate"])
            self.language = str(config.get("espeak", {}).get("voice", "en-us"))
            self.ids: dict[str, list[int]] = config["phoneme_id_map"]
            inference = config.get("inference", {})
        except (OSError, ValueError, KeyError, TypeError) as error:
            raise VoiceError(f"{files.config}: not a voice config ({error})") from None
        self.noise_scale = float(inference.get("noise_scale", 0.667))
        self.length_scale = float(inference.get("length_scale", 1.0))
        self.noise_w = float(inference.get("noise_w", 0.8))
        self.name = files.name
        options = onnxruntime.SessionOptions()
        options.intra_op_num_threads = threads
        options.inter_op_num_threads = 1
        providers = ["CPUExecutionProvider"]
        if use_cuda and "CUDAExecutionProvider" in onnxruntime.get_available_providers():
            providers.insert(0, "CUDAExecutionProvider")
        try:
            self.session = onnxruntime.InferenceSession(
                str(files.model), options, providers=providers
            )
        except Exception as error:  # onnxruntime raises its own untyped errors
            raise VoiceError(f"{files.model}: cannot load the voice ({error})") from None

    def steady(self) -> NeuralVoice:
        """This voice without its sampling noise: the same text always gives the same
        audio (for scripted people in scenarios and tests; a little flatter)."""
        twin = copy.copy(self)
        twin.noise_scale = twin.noise_w = 0.0
        return twin

    def phonemes(self, sentence: str) -> list[str]:
        """IPA phonemes, one character each (accents decomposed), with the clause marks."""
        lines = _espeak(["-q", "--ipa", "-v", self.language], sentence).decode().split("\n")
        clauses = [re.sub(r"\([^)]+\)", "", line).strip() for line in lines]
        clauses = [clause for clause in clauses if clause]
        marks = _CLAUSE_MARKS.findall(sentence)
        end = sentence.rstrip()[-1:] if sentence.rstrip()[-1:] in ".?!" else "."
        if len(marks) == len(clauses) - 1:
            text = "".join(c + m + " " for c, m in zip(clauses, marks, strict=False))
            text += clauses[-1] + end if clauses else ""
        else:
            text = " ".join(clauses) + end
        return list(unicodedata.normalize("NFD", text))

    def synthesize(self, sentence: str, *, speed: float = 1.0) -> Audio:
        ids = [*self.ids["^"], *self.ids["_"]]
        for phoneme in self.phonemes(sentence):
            if phoneme in self.ids:
                ids += [*self.ids[phoneme], *self.ids["_"]]
        ids += self.ids["$"]
        scales = np.array(
            [self.noise_scale, self.length_scale / max(speed, 0.1), self.noise_w],
            dtype=np.float32,
        )
        inputs = {
            "input": np.array([ids], dtype=np.int64),
            "input_lengths": np.array([len(ids)], dtype=np.int64),
            "scales": scales,
        }
        output = self.session.run(None, inputs)[0]
        samples = np.asarray(output, dtype=np.float32).reshape(-1)
        peak = float(np.max(np.abs(samples))) if len(samples) else 0.0
        if peak > 1e-8:
            samples = samples / peak * 0.9
        return Audio(samples.astype(np.float32), self.rate_hz)


HIBARI_LEAD_S = 0.05
HIBARI_TAIL_S = 0.2
"""Silence kept before and after a sentence of the hibari voice, seconds."""


class HibariVoice:
    """hibari's "heart" voice (PyPI hibari-tts, Apache-2.0: distilled from Kokoro-82M,
    Apache-2.0): its own spelling-to-sound rules and lexicons, no espeak-ng, an 8 MB ONNX
    model run by ONNX Runtime; 24 kHz. Only the voice inside the package is used: its
    other voices would be downloaded, and the robot downloads nothing."""

    def __init__(self, *, threads: int = 1, seed: int | None = None) -> None:
        """``seed``: None, a little different each time, as a person; a number, the same
        audio for the same text (:meth:`steady`)."""
        try:
            from hibari import Hibari
            from hibari.voices import voice_path

            model = voice_path("heart", download_missing=False)
            self.tts = Hibari(voice="heart", model=model, threads=threads)
        except ImportError:
            raise VoiceError("the hibari voice is not installed (pip package hibari-tts)") from None
        except Exception as error:  # its model missing, or onnxruntime refusing it
            raise VoiceError(f"the hibari voice cannot load ({error})") from None
        self.name = "hibari"
        self.rate_hz = int(self.tts.sample_rate)
        self.seed = seed
        self.synthesize("Hello.")  # its spelling rules load on first use: 0.3 s, not now

    def steady(self) -> HibariVoice:
        """This voice with its noise fixed: the same text always gives the same audio."""
        twin = copy.copy(self)
        twin.seed = 0
        return twin

    def synthesize(self, sentence: str, *, speed: float = 1.0) -> Audio:
        try:
            output = self.tts(sentence, speed=max(0.5, min(2.0, speed)), seed=self.seed)
        except Exception as error:  # its G2P or model failing on this text
            raise VoiceError(f"the hibari voice failed on {sentence[:40]!r} ({error})") from None
        samples = np.asarray(output, dtype=np.float32).reshape(-1)
        peak = float(np.max(np.abs(samples))) if len(samples) else 0.0
        if peak > 1e-8:
            samples = samples / peak * 0.9
        # it leaves about 0.3 s of silence before a sentence and 0.45 s after: cut to what
        # joe leaves, so the answer starts sooner and sentences follow as they would
        return Audio(samples, self.rate_hz).trimmed(lead_s=HIBARI_LEAD_S, tail_s=HIBARI_TAIL_S)


def steady_voice(voice: Voice) -> Voice:
    """``voice`` saying the same text the same way every time, where it can vary (the
    neural voices); espeak-ng always does."""
    if isinstance(voice, NeuralVoice | HibariVoice):
        return voice.steady()
    return voice
