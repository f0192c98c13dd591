"""What the echo canceller leaves of the robot's voice is told from another voice: the
residue lies on the robot's own harmonics, a child's voice between them."""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from engine.media.audio import SPEECH_RATE_HZ, Samples
from engine.speech.residual_echo import FIRST_FRAMES, FRAME_SAMPLES, ResidualEcho
from engine.speech.vad import BARGE_IN_PAUSE_THRESHOLD, BARGE_IN_THRESHOLD, SpeechDetector

RATE = SPEECH_RATE_HZ


def voice(f0_hz: float, seconds: float, seed: int) -> Samples:
    """A voiced sound: 20 harmonics of a pitch that wanders a little, its loudness rising
    and falling like syllables (4 a second)."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(seconds * RATE)) / RATE
    pitch = f0_hz * (1 + 0.03 * np.sin(2 * np.pi * 0.7 * t + rng.uniform(0, 6)))
    phase = 2 * np.pi * np.cumsum(pitch) / RATE
    sound = sum(np.sin(k * phase + rng.uniform(0, 6)) / k for k in range(1, 21))
    syllables = 0.55 + 0.45 * np.sin(2 * np.pi * 4 * t + rng.uniform(0, 6))
    return (0.1 * sound * syllables).astype(np.float32)


def room(seconds: float, seed: int) -> Samples:
    """A quiet room's noise at the canceller's output (-60 dBFS)."""
    rng = np.random.default_rng(seed)
    return (1e-3 * rng.standard_normal(round(seconds * RATE))).astype(np.float32)


def residue_of(played: Samples) -> Samples:
    """What a canceller leaves of the robot's voice: 18 dB below what it played, a little
    late and ringing, with some distortion of its own."""
    late = np.concatenate([np.zeros(200, np.float32), played])[: len(played)]
    ring = np.convolve(late, np.exp(-np.arange(800) / 300.0) / 40)[: len(played)]
    return (0.12 * (late + ring + 0.2 * np.tanh(3 * late))).astype(np.float32)


def unexplained(echo: ResidualEcho, heard: Samples, played: Samples) -> list[bool]:
    frames = range(0, len(heard) - FRAME_SAMPLES + 1, FRAME_SAMPLES)
    return [
        echo.unexplained(heard[at : at + FRAME_SAMPLES], played[at : at + FRAME_SAMPLES])
        for at in frames
    ]


def test_a_level_set_while_the_canceller_still_learns_gives_way_to_its_settled_residue() -> None:
    echo = ResidualEcho()
    played = voice(210.0, 1.0, seed=15)
    unsettled = 4.0 * residue_of(played) + room(1.0, seed=16)  # 12 dB more left
    for at in range(0, len(played) - FRAME_SAMPLES + 1, FRAME_SAMPLES):
        part = slice(at, at + FRAME_SAMPLES)
        echo.unexplained(unsettled[part], played[part], settled=False)
    assert echo.learned  # a first level: the robot may be interrupted as soon as it settles
    first = echo.residue_db
    played = voice(210.0, 3.0, seed=17)
    unexplained(echo, residue_of(played) + room(3.0, seed=18), played)
    levels = zip(echo.residue_db, first, strict=True)
    learned = [(now, before) for now, before in levels if before < 0]  # the voice's bands
    assert len(learned) >= 8 and all(now < before - 6 for now, before in learned)


def learned_on_the_robot_s_voice() -> ResidualEcho:
    echo = ResidualEcho()
    played = voice(210.0, 2.0, seed=1)
    unexplained(echo, residue_of(played) + room(2.0, seed=2), played)
    assert echo.learned
    return echo


def test_nothing_is_unexplained_before_the_robot_s_voice_taught_it_the_residue() -> None:
    echo = ResidualEcho()
    played = voice(210.0, 0.2, seed=3)
    child = voice(320.0, 0.2, seed=4)
    frames = unexplained(echo, residue_of(played) + child, played)
    assert len(frames) < FIRST_FRAMES and not any(frames)
    assert not echo.learned


def test_the_robot_s_own_residue_is_never_taken_for_another_voice() -> None:
    echo = learned_on_the_robot_s_voice()
    for seed in range(5, 10):  # new sentences, at another pitch, louder and softer
        played = voice(190.0 + 10 * seed, 3.0, seed=seed) * (0.5 + 0.2 * (seed - 5))
        assert not any(unexplained(echo, residue_of(played) + room(3.0, seed), played))


def test_a_child_under_the_robot_s_voice_is_found_in_its_first_frames() -> None:
    echo = learned_on_the_robot_s_voice()
    played = voice(210.0, 2.0, seed=11)
    residue = residue_of(played)
    child = voice(330.0, 2.0, seed=12)
    child[: RATE // 2] = 0.0  # the child starts half a second in
    # the child as loud as the residue: 12 dB under the robot's voice at the microphone
    child *= np.sqrt(np.mean(np.square(residue)) / np.mean(np.square(child[RATE // 2 :])))
    frames = unexplained(echo, residue + child + room(2.0, seed=13), played)
    first = (RATE // 2) // FRAME_SAMPLES  # the frame the child starts in
    assert not any(frames[:first])
    soon = frames[first : first + 4]  # within 0.13 s: two frames in a row
    assert any(a and b for a, b in pairwise(soon))


def test_the_room_s_noise_alone_is_not_another_voice() -> None:
    echo = learned_on_the_robot_s_voice()
    silent = np.zeros(RATE, np.float32)
    assert not any(unexplained(echo, room(1.0, seed=14), silent))


class Told(ResidualEcho):
    """A residual-echo check that says, frame after frame, what it is told to (and
    whether the robot's voice pauses there)."""

    def __init__(self, verdicts: list[bool], pauses: list[bool] | None = None) -> None:
        super().__init__()
        self.verdicts = iter(verdicts)
        self.pauses = iter(pauses or [False] * len(verdicts))

    def unexplained(self, heard: Samples, played: Samples, *, settled: bool = True) -> bool:
        self.pausing = next(self.pauses)
        return next(self.verdicts)


class SteadyVad:
    """A voice detector that gives every frame the same probability."""

    def __init__(self, probability: float) -> None:
        self.probability = probability

    def __call__(self, frame: Samples) -> float:
        return self.probability

    def reset(self) -> None:
        pass


def over_the_robot(
    verdicts: list[bool], probability: float = 0.9, pauses: list[bool] | None = None
) -> int | None:
    """Where speech began over the robot's voice, fed a frame per verdict (None: it did not)."""
    told = Told(verdicts, pauses)
    detector = SpeechDetector(
        SteadyVad(probability), noise_floor=None, residual_echo=told, strict=True
    )
    frames = np.full(len(verdicts) * FRAME_SAMPLES, 0.01, np.float32)
    detector.feed(frames, played=frames)
    return detector.take_onset()


def test_one_frame_the_robot_s_voice_cannot_explain_starts_nothing_two_in_a_row_do() -> None:
    assert over_the_robot([False, True, False, True, False]) is None
    assert over_the_robot([False, True, True, False]) == 1 * FRAME_SAMPLES


def test_a_sound_the_voice_detector_finds_no_voice_in_does_not_stop_the_robot() -> None:
    assert over_the_robot([True] * 10, probability=0.01) is None
    assert over_the_robot([True] * 10, probability=BARGE_IN_THRESHOLD) == 0


def test_while_the_robot_is_not_speaking_speech_starts_as_ever() -> None:
    detector = SpeechDetector(SteadyVad(0.9), noise_floor=None, residual_echo=Told([]))
    assert detector.feed(np.full(20 * FRAME_SAMPLES, 0.01, np.float32)) == []
    assert detector.in_speech and detector.take_onset() is None


def test_in_the_robot_s_pauses_its_room_s_tail_needs_a_voice_as_clear_as_in_silence() -> None:
    # where the robot pauses, the canceller lets the room's ringing through: what it
    # cannot explain there must sound like a voice in every frame, as to a silent robot
    unexplained, paused = [False, True, True, False], [False, True, False, False]
    assert over_the_robot(unexplained, probability=0.4, pauses=paused) is None
    assert over_the_robot(unexplained, probability=BARGE_IN_PAUSE_THRESHOLD, pauses=paused) == 512
    assert over_the_robot(unexplained, probability=0.4) == 512  # the robot did not pause
