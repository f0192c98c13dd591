"""The air around the simulated vest, as its microphone picks it up.

People's speech (a scenario's ``hear:`` events, synthesized or from a WAV), the robot's
own voice from its speaker (through the room's echo path,
:mod:`engine.sim.echo_path`: an echo the listener must not answer) and a quiet room hum
are mixed on one 16 kHz timeline; the microphone captures it piece by piece.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from engine.clock import Clock
from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.sim.echo_path import EchoPath

HUM_DBFS = -60.0
"""The room's background, RMS below full scale (a quiet therapy room)."""


@dataclass
class _Sound:
    start: int
    samples: np.ndarray
    source: str


class SimulatedRoom:
    """Sounds placed on the clock; :meth:`capture` mixes what the microphone heard."""

    def __init__(self, clock: Clock, *, hum_dbfs: float = HUM_DBFS, seed: int = 0) -> None:
        self.clock = clock
        self.origin_s = clock.now()
        self._captured = 0
        self._sounds: list[_Sound] = []
        self._hum = np.float32(10 ** (hum_dbfs / 20))
        self._rng = np.random.default_rng(seed)
        self._lock = threading.Lock()

    def _index(self, at_s: float) -> int:
        return max(0, round((at_s - self.origin_s) * SPEECH_RATE_HZ))

    def add(self, audio: Audio, at_s: float, source: str = "person") -> float:
        """``audio`` sounds from ``at_s`` (clock seconds); returns when it ends."""
        samples = audio.resampled(SPEECH_RATE_HZ).samples
        with self._lock:
            self._sounds.append(_Sound(self._index(at_s), samples, source))
        return at_s + len(samples) / SPEECH_RATE_HZ

    def silence_from(self, at_s: float, source: str) -> None:
        """Cut the sounds of ``source`` short at ``at_s`` (the speaker was stopped)."""
        cut = self._index(at_s)
        with self._lock:
            for sound in self._sounds:
                if sound.source == source and sound.start + len(sound.samples) > cut:
                    sound.samples = sound.samples[: max(0, cut - sound.start)]

    def capture(self, until_s: float) -> Audio:
        """What the microphone heard since the last capture, up to ``until_s``."""
        with self._lock:
            end = self._index(until_s)
            start, self._captured = self._captured, max(self._captured, end)
            count = max(0, end - start)
            mixed = self._rng.standard_normal(count).astype(np.float32) * self._hum
            keep: list[_Sound] = []
            for sound in self._sounds:
                lo, hi = max(start, sound.start), min(end, sound.start + len(sound.samples))
                if lo < hi:
                    mixed[lo - start : hi - start] += sound.samples[
                        lo - sound.start : hi - sound.start
                    ]
                if sound.start + len(sound.samples) > end:
                    keep.append(sound)
            self._sounds = keep
        return Audio(np.clip(mixed, -1.0, 1.0), SPEECH_RATE_HZ)


class RoomSpeaker:
    """The simulated vest's speaker: its sound reaches the microphone through the room's
    ``echo`` path. Implements :class:`~engine.speech.speaker.Playback`."""

    def __init__(self, room: SimulatedRoom, echo: EchoPath | None = None) -> None:
        self.room = room
        self.echo = echo or EchoPath()

    def start(self, audio: Audio, at_s: float) -> None:
        heard = self.echo.apply(audio.resampled(SPEECH_RATE_HZ).samples)
        self.room.add(Audio(heard, SPEECH_RATE_HZ), at_s, "robot")

    def stop(self, at_s: float) -> None:
        self.room.silence_from(at_s, "robot")
