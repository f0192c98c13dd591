"""Mono audio as float samples, WAV files, resampling and noise at a chosen SNR.

Samples are float32 in -1..1; ``rate_hz`` is samples per second. The recognizer and the
voice activity detector take 16 kHz (:data:`SPEECH_RATE_HZ`); voices make 22.05 kHz.
"""

from __future__ import annotations

import io
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from engine.errors import VestError
from engine.files.yaml_source import read_bytes

Samples = npt.NDArray[np.float32]
SPEECH_RATE_HZ = 16000
MAX_WAV_S = 600.0
MIN_WAV_RATE_HZ, MAX_WAV_RATE_HZ = 8000, 96000
"""The sample rates vest reads (speech needs 16 kHz; 96 kHz is a studio's most)."""
MAX_WAV_CHANNELS = 8
"""Longer recordings are refused: the robot hears utterances, not lectures."""


class AudioFileError(VestError, ValueError):
    """A WAV file that cannot be read, with its path and why."""


@dataclass(frozen=True)
class Audio:
    """Mono audio: ``samples`` (float32, -1..1) at ``rate_hz``."""

    samples: Samples
    rate_hz: int

    @property
    def seconds(self) -> float:
        return len(self.samples) / self.rate_hz

    @classmethod
    def silence(cls, seconds: float, rate_hz: int = SPEECH_RATE_HZ) -> Audio:
        return cls(np.zeros(round(seconds * rate_hz), dtype=np.float32), rate_hz)

    def resampled(self, rate_hz: int) -> Audio:
        """At ``rate_hz``, by linear interpolation after a moving-average low-pass when
        going down (enough for speech: the recognizer listens below 8 kHz)."""
        if rate_hz == self.rate_hz or len(self.samples) == 0:
            return Audio(self.samples, rate_hz) if len(self.samples) == 0 else self
        samples = self.samples
        if rate_hz < self.rate_hz:
            width = max(1, round(self.rate_hz / rate_hz))
            if width > 1:
                kernel = np.ones(width, dtype=np.float32) / width
                samples = np.convolve(samples, kernel, mode="same").astype(np.float32)
        count = round(len(samples) * rate_hz / self.rate_hz)
        at = np.linspace(0, len(samples) - 1, count, dtype=np.float64)
        # linear interpolation by index: memory for the output only, not for a float64 copy
        # of every input sample (np.interp needs one)
        below = np.minimum(at.astype(np.int64), len(samples) - 1)
        above = np.minimum(below + 1, len(samples) - 1)
        weight = (at - below).astype(np.float32)
        out = samples[below] * (1.0 - weight) + samples[above] * weight
        return Audio(out.astype(np.float32), rate_hz)

    def scaled(self, volume: float) -> Audio:
        """Louder or softer by ``volume`` (0..1 of full scale), clipped."""
        return Audio(np.clip(self.samples * volume, -1.0, 1.0).astype(np.float32), self.rate_hz)

    def trimmed(self, *, lead_s: float, tail_s: float, below: float = 0.01) -> Audio:
        """This audio with its silence cut to ``lead_s`` before the first sample and
        ``tail_s`` after the last sample louder than ``below`` times the peak (-40 dB);
        silence stays as it is."""
        loud = np.flatnonzero(
            np.abs(self.samples) > below * float(np.max(np.abs(self.samples), initial=0.0))
        )
        if len(loud) == 0:
            return self
        start = max(0, int(loud[0]) - round(lead_s * self.rate_hz))
        end = min(len(self.samples), int(loud[-1]) + 1 + round(tail_s * self.rate_hz))
        return Audio(self.samples[start:end], self.rate_hz)

    def then(self, other: Audio) -> Audio:
        """This audio followed by ``other`` (at this rate)."""
        other = other.resampled(self.rate_hz)
        return Audio(np.concatenate([self.samples, other.samples]), self.rate_hz)

    def pcm16(self) -> bytes:
        """16-bit little-endian PCM."""
        return (np.clip(self.samples, -1.0, 1.0) * 32767).astype("<i2").tobytes()

    @classmethod
    def from_pcm16(cls, data: bytes, rate_hz: int) -> Audio:
        usable = len(data) - len(data) % 2
        ints = np.frombuffer(data[:usable], dtype="<i2")
        return cls((ints.astype(np.float32) / 32768.0), rate_hz)

    def wav_bytes(self) -> bytes:
        buffer = io.BytesIO()
        with wave.open(buffer, "wb") as out:
            out.setnchannels(1)
            out.setsampwidth(2)
            out.setframerate(self.rate_hz)
            out.writeframes(self.pcm16())
        return buffer.getvalue()


def write_wav(path: Path, audio: Audio) -> None:
    """A 16-bit mono WAV file."""
    path.write_bytes(audio.wav_bytes())


MAX_WAV_BYTES = 128 * 1024 * 1024
"""The largest WAV file read (10 minutes of 48 kHz 16-bit stereo fit four times over)."""


def read_wav(path: Path) -> Audio:
    """A WAV file (8/16/32-bit PCM, any rate, channels mixed to mono). A LoadError when it
    cannot be read as a file (missing, a folder, a FIFO: never waited on), AudioFileError
    with the path and why when it is not a WAV we can use."""
    data = read_bytes(
        path, max_bytes=MAX_WAV_BYTES, kind="WAV file", too_big_hint="cut it to the utterance"
    )
    return wav_from_bytes(data, str(path))


def wav_from_bytes(data: bytes, name: str) -> Audio:
    """The audio of a WAV file's bytes. A header whose length is wrong (a recording made
    to a pipe says "as long as possible") is read for what the data holds."""
    if not data:
        raise AudioFileError(f"{name}: not a WAV file (it is empty)")
    dtypes: dict[int, str] = {1: "u1", 2: "<i2", 4: "<i4"}
    chunks: list[npt.NDArray[np.float32]] = []
    try:
        with wave.open(io.BytesIO(data), "rb") as wav:
            channels, width, rate = wav.getnchannels(), wav.getsampwidth(), wav.getframerate()
            if not MIN_WAV_RATE_HZ <= rate <= MAX_WAV_RATE_HZ:
                raise AudioFileError(
                    f"{name}: sample rate {rate} Hz; use {MIN_WAV_RATE_HZ} to {MAX_WAV_RATE_HZ} Hz"
                )
            if width not in dtypes:
                raise AudioFileError(f"{name}: {8 * width}-bit samples; use 8, 16 or 32-bit PCM")
            if not 1 <= channels <= MAX_WAV_CHANNELS:
                raise AudioFileError(f"{name}: {channels} channels; at most {MAX_WAV_CHANNELS}")
            most = round(MAX_WAV_S * rate)
            taken = 0
            while taken <= most:  # a second at a time, mixed to mono: memory for the mono
                raw = wav.readframes(rate)
                frames = len(raw) // (width * channels)
                if not frames:
                    break
                taken += frames
                chunks.append(_mono(raw[: frames * width * channels], dtypes[width], channels))
    except (wave.Error, EOFError) as error:
        if "unknown format: 3" in str(error):  # WAVE_FORMAT_IEEE_FLOAT
            raise AudioFileError(
                f"{name}: 32-bit float samples; use 8, 16 or 32-bit PCM (e.g. sox {name} "
                "-b 16 -e signed-integer out.wav)"
            ) from None
        raise AudioFileError(f"{name}: not a WAV file ({str(error) or 'cut short'})") from None
    if taken > most:
        raise AudioFileError(f"{name}: more than {MAX_WAV_S:.0f} s of audio")
    samples = np.concatenate(chunks) if chunks else np.zeros(0, dtype=np.float32)
    return Audio(samples, rate)


def _mono(raw: bytes, dtype: str, channels: int) -> npt.NDArray[np.float32]:
    """PCM frames as float32 samples, -1..1, the channels mixed."""
    ints = np.frombuffer(raw, dtype=dtype).astype(np.float32)
    width = np.dtype(dtype).itemsize
    scale = {1: 128.0, 2: 32768.0, 4: 2147483648.0}[width]
    samples = (ints - 128.0) / scale if width == 1 else ints / scale
    if channels > 1:
        samples = samples.reshape(-1, channels).mean(axis=1)
    return samples.astype(np.float32)


def with_noise(audio: Audio, snr_db: float, seed: int = 0) -> Audio:
    """``audio`` with white noise mixed in at ``snr_db`` decibels below the speech power
    (measured over the samples that are not silence); the same ``seed``, the same noise."""
    voiced = audio.samples[np.abs(audio.samples) > 1e-4]
    power = float(np.mean(voiced**2)) if len(voiced) else 1e-6
    noise = np.random.default_rng(seed).standard_normal(len(audio.samples)).astype(np.float32)
    noise *= np.float32(np.sqrt(power / 10 ** (snr_db / 10)))
    return Audio(np.clip(audio.samples + noise, -1.0, 1.0).astype(np.float32), audio.rate_hz)


def noise(seconds: float, level_dbfs: float, seed: int = 0, rate_hz: int = SPEECH_RATE_HZ) -> Audio:
    """White noise at ``level_dbfs`` (RMS, decibels below full scale): a room's hum."""
    count = round(seconds * rate_hz)
    samples = np.random.default_rng(seed).standard_normal(count).astype(np.float32)
    samples *= np.float32(10 ** (level_dbfs / 20))
    return Audio(samples, rate_hz)
