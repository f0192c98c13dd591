"""The vision worker: camera frames through the network onto the blackboard, a count
shown once it holds steady, and a camera that is pulled out and plugged back in."""

from __future__ import annotations

import numpy as np

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import VirtualClock
from engine.hardware.device_health import DeviceHealth
from engine.media.camera import CameraError
from engine.media.images import Frame
from engine.robot_io.hand_watcher import HandWatcher, SteadyCount
from engine.vision.classifier import HandReading

FINGERS, CONFIDENCE, SHOWN = "/vision/hand/fingers", "/vision/hand/confidence", "/vision/hand/shown"
CAMERA_OK = "/devices/camera/ok"


class PaperCamera:
    """A fake webcam: each frame is a 1x1 picture whose value is the finger count to see
    (255: no hand). ``plugged`` False makes it fail as an unplugged webcam does."""

    name = "camera"

    def __init__(self, counts: list[int | None]) -> None:
        self.counts = list(counts)
        self.plugged = True
        self.opened = 0

    def open(self) -> None:
        if not self.plugged:
            raise CameraError("camera: cannot be opened (unplugged)")
        self.opened += 1

    def read(self) -> Frame:
        if not self.plugged:
            raise CameraError("camera: gave no frame (unplugged?)")
        count = self.counts.pop(0) if len(self.counts) > 1 else self.counts[0]
        return np.full((1, 1), 255 if count is None else count, np.uint8)

    def close(self) -> None:
        pass


class ReadsTheNumber:
    """A fake network: the count is written on the frame."""

    def read(self, frame: Frame) -> HandReading:
        value = int(frame[0, 0])
        if value == 255:
            return HandReading(None, 0.3, (), False)  # no hand held up
        return HandReading(value, 0.95, ())


def watching(counts: list[int | None], steady_frames: int = 3):
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    camera = PaperCamera(counts)
    watcher = HandWatcher(
        camera,
        ReadsTheNumber(),
        board,
        clock,
        DeviceHealth("camera", board),
        fps=10.0,
        steady_frames=steady_frames,
    )
    return watcher, camera, board, clock


def run(watcher: HandWatcher, board: Blackboard, clock: VirtualClock, seconds: float) -> None:
    """Let the scheduler call the worker every 0.1 s, committing as it does."""
    end = clock.now() + seconds
    while clock.now() < end - 1e-9:
        clock.advance(0.1)
        watcher(clock.now())
        board.commit()


def shown(board: Blackboard) -> list[int]:
    return [event.value for event in board.event_log(SHOWN).events]


def test_a_count_is_shown_once_when_it_has_held_for_the_steady_frames() -> None:
    steady = SteadyCount(3)
    said = [steady.add(n) for n in (2, 2, 2, 2, 2)]
    assert said == [None, None, 2, None, None]


def test_a_flicker_is_not_shown() -> None:
    steady = SteadyCount(3)
    said = [steady.add(n) for n in (2, 2, 3, 2, 2, 2)]
    assert said == [None, None, None, None, None, 2]


def test_the_same_count_after_the_hand_went_away_is_shown_again() -> None:
    steady = SteadyCount(2)
    said = [steady.add(n) for n in (4, 4, None, None, 4, 4)]
    assert said == [None, 4, None, None, None, 4]


def test_a_brief_doubt_does_not_repeat_the_count() -> None:
    steady = SteadyCount(3)
    said = [steady.add(n) for n in (4, 4, 4, None, 4, 4, 4)]
    assert said == [None, None, 4, None, None, None, None]


def test_every_frame_stages_the_count_and_a_steady_one_is_an_event() -> None:
    watcher, _, board, clock = watching([None, None, 3, 3, 3, 3, 5, 5, 5, 5])
    run(watcher, board, clock, 1.0)
    assert watcher.frames == 10  # 10 fps for one second
    assert board.get(FINGERS) == 5 and board.get(CONFIDENCE) == 0.95
    assert shown(board) == [3, 5]


def test_not_sure_is_no_count_on_the_blackboard() -> None:
    watcher, _, board, clock = watching([3, 3, 3, None])
    run(watcher, board, clock, 0.6)
    assert board.get(FINGERS) is None
    assert board.get(CONFIDENCE) == 0.3


def test_a_camera_pulled_out_goes_offline_and_is_reopened_when_back() -> None:
    watcher, camera, board, clock = watching([2])
    run(watcher, board, clock, 0.5)
    assert board.get(FINGERS) == 2 and board.get(CAMERA_OK) is not False

    camera.plugged = False
    run(watcher, board, clock, 0.5)
    assert board.get(CAMERA_OK) is False
    assert board.get(FINGERS) is None  # nothing seen is no count, not the old one
    frames_before = watcher.frames

    run(watcher, board, clock, 3.0)  # still out: tried again every 2 s, no frames
    assert watcher.frames == frames_before
    assert camera.opened == 1

    camera.plugged = True
    run(watcher, board, clock, 2.5)
    assert camera.opened == 2  # re-opened at the next try
    assert board.get(CAMERA_OK) is True
    assert board.get(FINGERS) == 2
    assert shown(board) == [2, 2]  # the hand seen again after the outage is news


class NeedsTheWindow(ReadsTheNumber):
    """A fake network that, as the real one, needs frames the window fits in."""

    def read(self, frame: Frame) -> HandReading:
        if frame.shape[0] < 2:
            raise ValueError("a 1x1 image is smaller than the 2x2 window")
        return super().read(frame)


def test_frames_smaller_than_the_window_put_the_camera_offline_with_the_reason() -> None:
    watcher, _, board, clock = watching([3])
    watcher.model = NeedsTheWindow()
    run(watcher, board, clock, 0.5)
    assert board.get(CAMERA_OK) is False
    assert "smaller than the 2x2 window" in (watcher.health.last_error or "")
    assert watcher.frames == 0


def test_an_empty_view_that_does_not_change_is_read_once_in_ten_seconds() -> None:
    watcher, _, board, clock = watching([None])
    run(watcher, board, clock, 20.0)
    assert watcher.frames == 200  # every frame taken and staged...
    assert watcher.looked == 2  # ...but the finder read one every 10 s: nothing going on
    assert board.get(FINGERS) is None


def test_a_hand_coming_into_view_is_read_at_once_and_every_frame_while_it_is_there() -> None:
    watcher, _, board, clock = watching([None] * 5 + [3] * 5 + [None] * 5)
    run(watcher, board, clock, 1.5)
    assert shown(board) == [3]  # as without attention: the third frame of the hand
    assert watcher.looked == 1 + 5 + 3  # the empty view once; the hand; until it is gone
