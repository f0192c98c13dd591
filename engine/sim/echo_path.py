"""How the robot's own voice reaches its microphone on the simulated vest.

A robot's microphone hears its speaker a hand's width away: sooner and far louder than
any person in the room, colored by the room's reverberation and by the small speaker's
distortion. The simulated room plays the robot's voice through such a path (a scenario
may change it, or turn it off: ``echo:`` in docs/hardware-guide.md says how to measure a
real robot's), so the listener meets what it meets on a robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from engine.media.audio import SPEECH_RATE_HZ, Samples

ROOM_SEED = 41
"""The reverberation's random tail is the same on every run."""
DIRECT_OVER_REVERB_DB = 10.0
"""The speaker is close to the microphone: its direct sound is louder than the room's."""


@dataclass(frozen=True)
class EchoPath:
    """Speaker to microphone: ``delay_s`` (sound's travel and the sound card's buffers),
    ``gain_db`` (loudness at the microphone against what was played), ``rt60_s`` (the
    room's reverberation: seconds for it to fall 60 dB), ``distortion`` (0: none; 1: a
    small speaker driven hard). ``on``: False, the microphone does not hear the robot."""

    delay_s: float = 0.012
    gain_db: float = -6.0
    rt60_s: float = 0.35
    distortion: float = 0.3
    on: bool = True

    def __post_init__(self) -> None:
        checks = (
            (0.0 <= self.delay_s <= 0.5, "delay_s must be 0 to 0.5 s"),
            (-60.0 <= self.gain_db <= 20.0, "gain_db must be -60 to 20 dB"),
            (0.0 <= self.rt60_s <= 2.0, "rt60_s must be 0 to 2 s"),
            (0.0 <= self.distortion <= 1.0, "distortion must be 0 to 1"),
        )
        for fine, why in checks:
            if not fine:
                raise ValueError(why)

    def response(self) -> Samples:
        """The room's impulse response (16 kHz): the direct sound, then a tail of
        reflections falling 60 dB in ``rt60_s``, :data:`DIRECT_OVER_REVERB_DB` below it."""
        length = max(1, round(self.rt60_s * SPEECH_RATE_HZ))
        decay = 6.9 / max(self.rt60_s * SPEECH_RATE_HZ, 1.0)  # per sample, in nepers
        tail = np.random.default_rng(ROOM_SEED).standard_normal(length)
        tail *= np.exp(-decay * np.arange(length))
        energy = float(np.sum(np.square(tail[1:]))) or 1.0
        tail *= np.sqrt(10 ** (-DIRECT_OVER_REVERB_DB / 10) / energy)
        tail[0] = 1.0
        return tail.astype(np.float32)

    @classmethod
    def measured(cls, played: Samples, heard: Samples) -> EchoPath:
        """The path that made ``heard`` (the microphone, 16 kHz) of ``played`` (what the
        speaker played, from the same moment): the delay where they match best, the direct
        sound's gain, and the room's rt60 from the decay of the response (Schroeder's
        backward integration, fitted from -5 to -25 dB). Distortion is not measured (it
        stays the default). ValueError when ``played`` is silent, or ``heard`` holds
        nothing of it that stands out of its noise, or later than 0.5 s (a delay the
        simulation does not model: start the recording and the playing together)."""
        if not np.any(played):
            raise ValueError("what was played is silent")
        size = 1 << (len(played) + len(heard) - 1).bit_length()
        spectrum = np.fft.rfft(played, size)
        power = np.abs(spectrum) ** 2
        ratio = np.fft.rfft(heard, size) * np.conj(spectrum) / (power + 1e-3 * power.mean())
        response = np.fft.irfft(ratio, size)[: 4 * SPEECH_RATE_HZ]
        lag = int(np.argmax(np.abs(response[: 3 * SPEECH_RATE_HZ])))
        direct = float(np.abs(response[lag]))
        noise = float(np.median(np.abs(response[: 3 * SPEECH_RATE_HZ])))
        if direct < 1e-4 or direct < 20 * noise:
            raise ValueError("the recording holds nothing that stands out of what was played")
        if lag > SPEECH_RATE_HZ // 2:
            raise ValueError(
                f"the robot's voice comes {lag / SPEECH_RATE_HZ:.2f} s into the recording, "
                "later than 0.5 s: start the recording and the playing together"
            )
        return cls(
            delay_s=lag / SPEECH_RATE_HZ,
            gain_db=float(np.clip(20 * np.log10(direct), -60.0, 20.0)),
            rt60_s=float(np.clip(_rt60_s(response[lag + round(0.003 * SPEECH_RATE_HZ) :]), 0, 2)),
        )

    def apply(self, played: Samples) -> Samples:
        """What the microphone hears of ``played`` (16 kHz), delay included: longer by the
        delay and the reverberation's tail; nothing when the path is off."""
        if not self.on:
            return np.zeros(0, dtype=np.float32)
        heard = np.convolve(played, self.response())
        if self.distortion > 0:
            drive = 1.0 + 4.0 * self.distortion
            heard = np.tanh(drive * heard) / drive
        delay = np.zeros(round(self.delay_s * SPEECH_RATE_HZ), dtype=np.float32)
        gain = np.float32(10 ** (self.gain_db / 20))
        return np.concatenate([delay, heard.astype(np.float32) * gain])


def _rt60_s(tail: npt.NDArray[np.floating[Any]]) -> float:
    """Seconds for the reflections in ``tail`` (a response after its direct sound) to fall
    60 dB: the energy still to come, from where it falls 5 dB to where it falls 25 dB,
    extrapolated; the response's noise floor (its level 2 to 3 s on) is taken out first."""
    energy = np.square(tail[: 3 * SPEECH_RATE_HZ].astype(np.float64))
    floor = float(np.mean(energy[2 * SPEECH_RATE_HZ :]))
    envelope = np.convolve(energy, np.ones(160) / 160, mode="same")
    below = np.nonzero(envelope < 2 * floor)[0]
    energy = np.clip(energy[: below[0] if len(below) else len(energy)] - floor, 0, None)
    to_come = np.cumsum(energy[::-1])[::-1]
    if len(to_come) < 10 or to_come[0] <= 0:
        return 0.0
    decay_db = 10 * np.log10(to_come / to_come[0] + 1e-12)
    fitted = (decay_db <= -5) & (decay_db >= -25)
    if fitted.sum() < 10:
        return 0.0
    times_s = np.arange(len(decay_db)) / SPEECH_RATE_HZ
    slope = float(np.polyfit(times_s[fitted], decay_db[fitted], 1)[0])
    return -60.0 / slope if slope < 0 else 0.0
