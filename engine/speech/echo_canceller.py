"""Echo cancellation: the robot's own voice taken out of what its microphone hears.

The robot's microphone hears its speaker far louder than a person across the table (a
vest's speaker is a hand's width from the microphone). To listen while it speaks, the
listener subtracts the robot's voice, known sample for sample (the *reference*: what the
speaker was given, placed on the clock, :class:`~engine.speech.speaker.SelfHearing`),
with WebRTC's acoustic echo canceller (AEC3, in its audio processing module, from the
``livekit`` wheel: Apache-2.0). It learns the room's echo path (delay, loudness,
reverberation) as the robot speaks and keeps learning; a little of the echo remains (its
residual, about 30 dB below the echo), which :mod:`engine.speech.residual_echo` keeps from
being taken for a person: it is the robot's voice still, and a voice detector finds speech
in it.

Measured on the same recordings against SpeexDSP's canceller (``pyaec``): 32 dB of echo
removed against 16, 4 % of the residual's frames over the VAD's threshold against 26 %
(bench/bench_barge_in.py).

The canceller works on 10 ms frames; the samples of a piece that do not fill one wait for
the next piece, so its output lags the microphone by less than 10 ms (:attr:`lag_samples`).
When the robot has been silent for :data:`RESTS_AFTER_S` it passes the microphone through
untouched and costs nothing: an idle robot listens as cheaply as it did without one.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from engine.media.audio import SPEECH_RATE_HZ, Samples

FRAME = SPEECH_RATE_HZ // 100
"""Samples in one of the canceller's 10 ms frames."""
RESTS_AFTER_S = 30.0
"""Seconds after the robot's voice (its reference) fell silent before the canceller rests."""
LEARNED_DB = 20.0
"""The canceller has learned the echo path (from the start, and after a rest) once it takes
this much of the robot's voice out, over :data:`LEARNING_S`: until then a person's voice
cannot be told from the rest of the robot's, and nobody can stop the robot
(:attr:`EchoCanceller.learned`)."""
LEARNING_S = 0.5
"""The time over which the echo taken out is measured (an exponential average)."""
LEARNS_AT_LEAST_S = 1.5
"""It is not judged learned before it has heard this much of the robot's voice."""
SCALE = 32767.0


class Cancelled(NamedTuple):
    """A piece of the microphone's audio with the robot's voice taken out, and what the
    speaker played over the same samples (16 kHz, as long as ``heard``)."""

    heard: Samples
    played: Samples


class NoEchoCancellerError(RuntimeError):
    """The package that cancels echo is not installed (the robot then does not listen while
    it speaks)."""


class EchoCanceller:
    """Takes the reference out of the microphone's audio, 16 kHz, piece by piece."""

    name = "WebRTC AEC3"

    def __init__(self) -> None:
        try:
            from livekit import rtc
        except ImportError as error:
            raise NoEchoCancellerError(
                f"no echo canceller ({error}); install vest's speech extras"
            ) from None
        self._rtc = rtc
        self._module = rtc.AudioProcessingModule(echo_cancellation=True)
        self._module.set_stream_delay_ms(0)
        self._microphone = np.zeros(0, dtype=np.float32)
        self._reference = np.zeros(0, dtype=np.float32)
        self._silent_frames = RESTS_AFTER_S * 100  # resting until the robot first speaks
        self._learned = False
        self._heard_power = self._left_power = 0.0  # while the robot speaks, averaged
        self._voice_frames = 0  # frames of the robot's voice since the last rest

    @property
    def lag_samples(self) -> int:
        """Samples of the microphone waiting for a whole frame (fewer than :data:`FRAME`)."""
        return len(self._microphone)

    @property
    def learned(self) -> bool:
        """Whether it has taken :data:`LEARNED_DB` of the robot's voice out since it last
        rested (it stays learned until it rests)."""
        return self._learned

    @property
    def resting(self) -> bool:
        """Whether the robot has been silent long enough that the audio passes untouched."""
        return self._silent_frames >= RESTS_AFTER_S * 100

    def cancel(self, microphone: Samples, reference: Samples) -> Cancelled:
        """The microphone's audio with the reference's echo taken out: the same number of
        samples as given, less :attr:`lag_samples` waiting, plus those that waited; with
        the reference over those very samples. ``reference``: what the speaker played
        over the same samples as ``microphone`` (same length)."""
        if len(reference) != len(microphone):
            raise ValueError("the reference must be as long as the microphone's piece")
        self._microphone = np.concatenate([self._microphone, microphone.astype(np.float32)])
        self._reference = np.concatenate([self._reference, reference.astype(np.float32)])
        whole = len(self._microphone) // FRAME * FRAME
        near, self._microphone = self._microphone[:whole], self._microphone[whole:]
        far, self._reference = self._reference[:whole], self._reference[whole:]
        out = near.copy()
        for start in range(0, whole, FRAME):
            far_frame = far[start : start + FRAME]
            speaking = bool(np.any(far_frame))
            self._silent_frames = 0 if speaking else self._silent_frames + 1
            if self.resting:
                self._learned, self._heard_power, self._left_power = False, 0.0, 0.0
                self._voice_frames = 0
                continue
            heard = near[start : start + FRAME]
            left = out[start : start + FRAME] = self._frame(heard, far_frame)
            if speaking and not self._learned:
                self._learn(heard, left)
        return Cancelled(out, far)

    def _learn(self, heard: Samples, left: Samples) -> None:
        """Average how much of the robot's voice is taken out; learned past LEARNED_DB."""
        weight = 0.01 / LEARNING_S  # one 10 ms frame of the average's time
        self._heard_power += weight * (float(np.mean(np.square(heard))) - self._heard_power)
        self._left_power += weight * (float(np.mean(np.square(left))) - self._left_power)
        self._voice_frames += 1
        taken_out = self._heard_power / max(self._left_power, 1e-12)
        self._learned = self._voice_frames >= LEARNS_AT_LEAST_S * 100 and taken_out >= 10 ** (
            LEARNED_DB / 10
        )

    def _frame(self, near: Samples, far: Samples) -> Samples:
        rtc = self._rtc
        played = rtc.AudioFrame(_pcm(far), SPEECH_RATE_HZ, 1, FRAME)
        self._module.process_reverse_stream(played)
        heard = rtc.AudioFrame(_pcm(near), SPEECH_RATE_HZ, 1, FRAME)
        self._module.process_stream(heard)
        return np.frombuffer(bytes(heard.data), dtype=np.int16).astype(np.float32) / SCALE


def _pcm(samples: Samples) -> bytes:
    return bytes((np.clip(samples, -1.0, 1.0) * SCALE).astype(np.int16).tobytes())
