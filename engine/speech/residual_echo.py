"""What the echo canceller leaves of the robot's own voice, and what it cannot explain.

The echo canceller (:mod:`engine.speech.echo_canceller`) takes most of the robot's voice
out of the microphone, but not all: a residue remains where the room rings, where the
speaker distorts, and while the canceller follows a change. That residue *is* speech (the
robot's), so a voice detector finds speech in it; and a child's voice, 12 dB below the
robot's at the microphone, is partly taken out with it. The two are told apart here, in
the fine spectrum (31 Hz bins): the residue lies where the robot's voice has energy (its
harmonics, over the last frames, as the room rings), below a level learned as the robot
speaks; another voice has its own harmonics, between the robot's.

Each 32 ms frame of the canceller's output is compared, bin by bin, with what the robot
played (its *reference*, known sample for sample) over the same frame and the ones just
before, smeared by the room's decay: a bin is *unexplained* when it rises
:data:`OVER_RESIDUE` above the most the residue has reached there (learned: a high
quantile of the output's ratio to the reference, band by band, while no other voice is
heard) and above the room's noise. A frame holds a voice that is not the robot's when
:data:`UNEXPLAINED_SHARE` of its energy is in unexplained bins
(:meth:`ResidualEcho.unexplained`).

In a pause of the robot's voice, where the canceller lets the room's tail through as it
lets go of the voice, the level is not learned, and the voice detector is asked as when
the robot is silent (:attr:`ResidualEcho.pausing`).

The thresholds were chosen with ``bench/bench_barge_in.py --tuning``; its figures on the
held-back children are in docs/speech.md (none of the robot's 368 sentences stopped it,
where the voice detector alone stopped it 3 times; a child 12 dB under the robot's echo
stops it within 0.23 s, p90). Its cost: two 512-point FFTs a frame, only while the robot
speaks.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
import numpy.typing as npt

from engine.media.audio import SPEECH_RATE_HZ, Samples

Power = npt.NDArray[np.float64]
"""Power in each compared bin (or band)."""

FRAME_SAMPLES = 512
"""One frame: 32 ms at 16 kHz (the voice detector's)."""
LOW_HZ, HIGH_HZ = 125.0, 6250.0
"""The bins compared: where voices have their harmonics."""
BANDS = 12
"""The residue's level is learned in this many bands of equal width."""
NEIGHBOURS = 1
"""A harmonic of the reference covers this many bins either side (a Hann window's main
lobe, and a voice's pitch moving within a frame)."""
RECENT_FRAMES = 2
"""The reference's frames just before count whole (the canceller's delay and the room's
first reflections)."""
ROOM_DECAY_PER_FRAME = 0.69
"""How much of the reference's energy still rings one frame later (power): 1.6 dB per
32 ms, a room whose reverberation falls 60 dB in 1.2 s (larger and barer than the bench's
most reverberant, 0.8 s: the margin that keeps its self-interruptions at none)."""
PAUSE_BELOW = 0.1
"""A frame is in a pause of the robot's voice (the room still ringing with it) when what
the robot plays is this far (10 dB) below the ringing. The canceller's residue there is
the room's tail, which it takes out less well than the voice, and which varies as it
lets go of the voice: the level is learned from the robot's voice alone, and the voice
detector judges a pause (:attr:`ResidualEcho.pausing`)."""
OVER_RESIDUE = 2.0
"""A bin is unexplained from this many times (power; 3 dB) the most the residue has
reached there."""
OVER_NOISE = 10.0
"""... and this many times (10 dB) the room's noise in that bin."""
UNEXPLAINED_SHARE = 0.2
"""A frame holds another voice when this share of its energy is in unexplained bins."""
RESIDUE_QUANTILE = 0.99
"""The residue's level is this quantile of the output's ratio to the reference."""
FIRST_FRAMES = 8
"""The residue's level is first set once this many frames of the robot's voice (0.26 s)
were learned, from what the canceller leaves while it still learns the room (high: few
sounds are unexplained; nobody may start over the robot before it has settled)."""
SETTLED_FRAMES = 32
"""Once the canceller has settled, the level is set again from what it leaves then, as
soon as this many frames (1 s) of it were learned: fewer let a quiet stretch of the
robot's voice set it too low."""
RECENT_VOICE_FRAMES = 64
"""Then it is the quantile over the last 2 s of the robot's voice: it follows the
canceller as it settles further, or as the room changes."""
NOISE_RISES_PER_FRAME = 10 ** (2.0 * FRAME_SAMPLES / SPEECH_RATE_HZ / 10)
"""The room's noise estimate rises 2 dB a second when the room grows louder for good."""
NOISE_FLOOR = 1e-12
"""The least the room's noise in a bin is taken to be (power: a silent microphone)."""
LEARNS_OVER_NOISE = 30.0
"""The level is learned in the bins where the reference stands this far (15 dB) above
the room's noise in the output: where the residue can be heard."""
STARTING_LEVEL = 1.0
"""The residue's level before anything is learned: as loud as the reference itself
(nothing is taken for another voice until the level is learned)."""


class ResidualEcho:
    """Frame by frame (:data:`FRAME_SAMPLES`), whether the canceller's output holds a
    sound the robot's own voice cannot explain."""

    def __init__(self) -> None:
        bin_hz = SPEECH_RATE_HZ / FRAME_SAMPLES
        self._low, self._high = round(LOW_HZ / bin_hz), round(HIGH_HZ / bin_hz)
        width = self._high - self._low
        self._band = np.minimum(np.arange(width) * BANDS // width, BANDS - 1)
        self._band_bins = np.bincount(self._band, minlength=BANDS)
        self._window = np.hanning(FRAME_SAMPLES).astype(np.float32)
        self._level = _Level(self._band)
        self.pausing = False
        """The last frame was in a pause of the robot's voice, or after it: the room rang
        with it, and the canceller may let that through (:data:`PAUSE_BELOW`)."""
        self._settled = False
        self._recent: list[Power] = []
        self._ringing = np.zeros(width)
        self._noise: Power | None = None

    @property
    def learned(self) -> bool:
        """Whether the residue's level has been set (:data:`FIRST_FRAMES`); until then no
        sound is unexplained, and the listener lets nobody start over the robot."""
        return self._level.learned

    @property
    def residue_db(self) -> list[float]:
        """The level learned for each band while the robot's voice plays: the most the
        residue reaches against the reference, dB."""
        return [round(10 * float(level) / math.log(10), 1) for level in self._level.log_level]

    def unexplained(self, heard: Samples, played: Samples, *, settled: bool = True) -> bool:
        """Whether ``heard`` (one frame of the canceller's output) holds a sound that is
        not what is left of ``played`` (the reference over the same samples) and the
        frames played before it. Every frame while the robot speaks must be given: the
        room's ringing and noise are followed from them. ``settled``: False while the
        canceller itself still learns the room: what it leaves then sets a first level,
        forgotten once it has settled and left :data:`FIRST_FRAMES` of its residue."""
        if settled and not self._settled:
            self._level.forget_frames()
        self._settled = settled
        if not (np.all(np.isfinite(heard)) and np.all(np.isfinite(played))):
            return False  # a broken frame teaches nothing and tells nothing
        output = self._spectrum(heard)
        playing = self._spectrum(played)
        reference = self._spread(playing)
        noise = self._follow_noise(output)
        self.pausing = bool(np.sum(playing) < PAUSE_BELOW * np.sum(reference))
        residue = self._level.level() * reference
        unexplained = (output > OVER_RESIDUE * residue) & (output > OVER_NOISE * noise)
        share = float(np.sum(output[unexplained])) / (float(np.sum(output)) + 1e-20)
        if share >= UNEXPLAINED_SHARE:  # never learned from, even before a level is set
            return self.learned
        heard_bins = reference > LEARNS_OVER_NOISE * noise
        if not self.pausing and np.any(heard_bins):
            self._level.learn(output[heard_bins], reference[heard_bins], heard_bins)
        return False

    def _spectrum(self, frame: Samples) -> Power:
        spectrum = np.fft.rfft(frame[:FRAME_SAMPLES] * self._window)
        power: Power = np.square(np.abs(spectrum[self._low : self._high]))
        return power

    def _spread(self, played: Power) -> Power:
        """The reference's energy where its echo may still be: its bins and their
        neighbours, over the recent frames, and ringing down since."""
        wide = played.copy()
        for shift in range(1, NEIGHBOURS + 1):
            wide[shift:] = np.maximum(wide[shift:], played[:-shift])
            wide[:-shift] = np.maximum(wide[:-shift], played[shift:])
        self._ringing = np.maximum(wide, ROOM_DECAY_PER_FRAME * self._ringing)
        spread = self._ringing.copy()
        for recent in self._recent:
            spread = np.maximum(spread, recent)
        self._recent = [*self._recent[-(RECENT_FRAMES - 1) :], wide]
        return spread

    def _follow_noise(self, output: Power) -> Power:
        """The room's noise in each bin: the band's mean power (steadier than one bin's)
        falls at once to a quieter frame's and rises slowly."""
        mean = np.bincount(self._band, weights=output, minlength=BANDS) / self._band_bins
        mean = np.maximum(mean, NOISE_FLOOR)  # a silent frame must not hold it at 0
        if self._noise is None:
            self._noise = mean
        else:
            self._noise = np.minimum(mean, self._noise * NOISE_RISES_PER_FRAME)
        noise: Power = self._noise[self._band]
        return noise


class _Level:
    """How loud the residue gets against the reference, band by band: the quantile of
    their ratio over the recent frames (:data:`RECENT_VOICE_FRAMES`), set once there are
    :data:`FIRST_FRAMES` of them (until then: :data:`STARTING_LEVEL`)."""

    def __init__(self, band: npt.NDArray[np.intp]) -> None:
        self._band = band
        self.log_level = np.full(BANDS, math.log(STARTING_LEVEL))
        self.learned = False
        self._needed = FIRST_FRAMES  # frames learned before the level is set
        # the recent frames: the band of each bin heard, and its ratio (nepers)
        self._frames: deque[tuple[npt.NDArray[np.intp], Power]] = deque(maxlen=RECENT_VOICE_FRAMES)

    def forget_frames(self) -> None:
        """Forget the frames learned so far: their level stays until
        :data:`SETTLED_FRAMES` new ones set it."""
        self._frames.clear()
        self._needed = SETTLED_FRAMES

    def level(self) -> Power:
        """The level of each bin (power ratio)."""
        level: Power = np.exp(self.log_level)[self._band]
        return level

    def learn(self, output: Power, reference: Power, bins: npt.NDArray[np.bool_]) -> None:
        """One more frame: the output and reference in the ``bins`` heard."""
        self._frames.append((self._band[bins], np.log(output + 1e-20) - np.log(reference)))
        if len(self._frames) < self._needed:
            return
        bands = np.concatenate([bands for bands, _ in self._frames])
        ratios = np.concatenate([ratios for _, ratios in self._frames])
        for band in range(BANDS):
            mine = ratios[bands == band]
            if len(mine):
                self.log_level[band] = float(np.quantile(mine, RESIDUE_QUANTILE))
        self.learned = True
