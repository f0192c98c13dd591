"""The vision worker: camera frames through the hand finder onto the blackboard.

Every frame it stages ``/vision/hand/fingers`` (0..5, or None when no hand is held up or
its count is not sure), ``/vision/hand/confidence`` and ``/vision/hand/box`` (where the
hand is, px, or None); when a count changes and holds for
``steady_frames`` frames it stages one ``/vision/hand/shown`` event, and
``/vision/hand/held`` keeps that count until another (or no hand) holds as long. Trees only read
the blackboard: the camera, the preprocessing and the network never run in a tick.

On a real clock it is a thread (:meth:`start`): it reads a frame when one is due at the
camera's rate, and a frame that comes while the network is still busy is dropped, never
queued (the camera keeps one frame; the next deadline skips ahead). On a virtual clock
(``vest run --fast``, the tests) the scheduler calls it as a hook and it reads the frames
due by then, in order, so a run is the same every time.

The camera is a device like the chips: ``/devices/<camera>/ok`` is False while it gives
no frames, and it is re-opened every ``reopen_s`` until it answers again.

Attention, not a timer (the paper's "attention activation"): while no hand is seen and
nothing is shown, a frame that looks like the last one the finder read (each cell of a
16 x 9 grid of its grey levels within ``STILL_LEVELS``) is not read again: the reading
stays "no hand". Something coming into view changes the cells and is read at once; the
finder still reads a frame at least every 10 s (``LOOK_AT_LEAST_EVERY_S``), so a
change too small for the grid is never missed for long.
"""

from __future__ import annotations

import logging

import cv2
import numpy as np

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import (
    HAND_BOX,
    HAND_CONFIDENCE,
    HAND_FINGERS,
    HAND_HELD,
    HAND_SHOWN,
)
from engine.clock import Clock
from engine.hardware.device_health import DeviceHealth
from engine.media.camera import Camera, CameraError
from engine.media.images import Frame
from engine.periodic import WorkerHook, WorkerThread
from engine.vision.classifier import FingerCounter, HandReading

log = logging.getLogger(__name__)
STILL_LEVELS = 6.0
"""How far (grey levels, 0..255) a cell of the grid may move and the view still count as
the same: above a webcam's noise averaged over a cell, far below a hand coming in."""
GRID = (16, 9)
GRID_STRIDE = 4
LOOK_AT_LEAST_EVERY_S = 10.0
"""How often the finder looks at a view with no hand that has not changed: its palm
detector costs about 15 ms a frame, so once in 10 s keeps an idle robot's camera at what it
cost with the paper's network once a second (bench/bench_cpu.py: once a second, 4.9 % of
a core against 3.8 %; once in 5 s, 3.9 % against 3.7 %)."""
REOPEN_S = 2.0


def _box(reading: HandReading, frame: Frame) -> dict[str, int] | None:
    """Where the hand is, and in what size of frame (px), as ``/vision/hand/box`` holds it."""
    if reading.box is None:
        return None
    x, y, width, height = reading.box
    return {
        "x": x,
        "y": y,
        "width": width,
        "height": height,
        "frame_width": int(frame.shape[1]),
        "frame_height": int(frame.shape[0]),
    }


class SteadyCount:
    """Turns per-frame counts into events: a count is *shown* once it changes and holds
    for ``steady_frames`` frames in a row. "No count" that holds as long ends what was
    shown, so the same count shown again is a new event."""

    def __init__(self, steady_frames: int) -> None:
        self.steady_frames = steady_frames
        self.shown: int | None = None
        self._candidate: int | None = None
        self._streak = 0

    def reset(self) -> None:
        """Forget what was shown (the camera saw nothing for a while)."""
        self.shown, self._candidate, self._streak = None, None, 0

    def add(self, fingers: int | None) -> int | None:
        """The count newly shown by this frame, or None."""
        if fingers == self._candidate:
            self._streak += 1
        else:
            self._candidate, self._streak = fingers, 1
        if self._streak != self.steady_frames or fingers == self.shown:
            return None
        self.shown = fingers
        return fingers


class HandWatcher:
    """Reads ``camera`` at ``fps`` frames a second, finds and counts a hand with ``model``
    (a :class:`~engine.vision.hand_finder.HandFinder`) and
    stages the results on ``blackboard``; ``health`` is the camera's device health."""

    def __init__(
        self,
        camera: Camera,
        model: FingerCounter,
        blackboard: Blackboard,
        clock: Clock,
        health: DeviceHealth,
        *,
        fps: float,
        steady_frames: int,
        reopen_s: float = REOPEN_S,
    ) -> None:
        self.name = "vision"
        self.camera, self.model = camera, model
        self.blackboard, self.clock, self.health = blackboard, clock, health
        self.period_s = 1.0 / fps
        self.reopen_s = reopen_s
        self.steady = SteadyCount(steady_frames)
        self.frames = 0
        self.dropped = 0
        self.looked = 0
        """Frames the network read (the others looked like the last one, with no hand)."""
        self._seen: np.ndarray | None = None  # the grid of the last frame the network read
        self._seen_s = float("-inf")
        self._last: HandReading | None = None
        self._open = False
        self._next_s: float | None = None
        self._retry_s = 0.0
        self._hook = WorkerHook(self)
        self._worker: WorkerThread | None = None

    # -- one frame ------------------------------------------------------------------------
    def process(self, frame: Frame) -> HandReading:
        """Count the fingers in ``frame`` (or, when nothing is going on and it looks like
        the last frame read, keep that reading) and stage what was seen."""
        grid = _grid(frame)
        now_s = self.clock.now()
        last = self._last
        if (
            last is None
            or last.present
            or self.steady.shown is not None
            or self._seen is None
            or now_s - self._seen_s >= LOOK_AT_LEAST_EVERY_S
            or float(np.abs(grid - self._seen).max()) > STILL_LEVELS
        ):
            last = self._last = self.model.read(frame)
            self._seen, self._seen_s = grid, now_s
            self.looked += 1
        reading = last
        self.frames += 1
        self.blackboard.stage(HAND_FINGERS, reading.fingers)
        self.blackboard.stage(HAND_CONFIDENCE, round(reading.confidence, 4))
        self.blackboard.stage(HAND_BOX, _box(reading, frame))
        held = self.steady.shown
        shown = self.steady.add(reading.fingers)
        if shown is not None:
            self.blackboard.stage_event(HAND_SHOWN, shown)
        if self.steady.shown != held:
            self.blackboard.stage(HAND_HELD, self.steady.shown)
        return reading

    def take_frame(self) -> HandReading | None:
        """Open the camera if it is not (at most every ``reopen_s``), read one frame and
        process it; None when the camera gives none (it is then offline)."""
        now = self.clock.now()
        if not self._open:
            if now < self._retry_s:
                return None
            try:
                self.camera.open()
            except CameraError as error:
                self._failed(str(error), now)
                return None
            self._open = True
            self.health.driver_status(True)
        try:
            frame = self.camera.read()
            return self.process(frame)
        except CameraError as error:
            self.camera.close()
            self._open = False
            self._failed(str(error), now)
        except ValueError as error:  # frames the window does not fit (a camera's own size)
            self.camera.close()
            self._open = False
            self._failed(f"{self.camera.name}: {error}", now)
        return None

    def _failed(self, why: str, now_s: float) -> None:
        if self.health.driver_ok:
            log.info("%s; trying again every %g s", why, self.reopen_s)  # the timeline says so
            self.blackboard.stage(HAND_FINGERS, None)
            self.blackboard.stage(HAND_CONFIDENCE, None)
            self.blackboard.stage(HAND_BOX, None)
            if self.steady.shown is not None:
                self.blackboard.stage(HAND_HELD, None)
            self.steady.reset()
        self.health.driver_status(False, why)
        self._retry_s = now_s + self.reopen_s

    # -- as a worker (engine.periodic): a scheduler hook inline, a thread on a real clock --
    def due_s(self) -> float:
        """When the next frame is due (clock seconds)."""
        if self._next_s is None:
            self._next_s = self.clock.now()
        return self._next_s

    def run(self, now_s: float) -> None:
        """Take the frame due at ``now_s``."""
        try:
            self.take_frame()
        finally:
            self._next_s = self.due_s() + self.period_s

    def __call__(self, now_s: float) -> None:
        """On a virtual clock, a scheduler hook: every frame due by ``now_s``, in order."""
        self._hook(now_s)

    def start(self) -> None:
        """Start the worker thread (real clock)."""
        if self._worker is None:
            self._next_s = None
            self._worker = WorkerThread(_InRealTime(self), self.clock, after=self._close)
        self._worker.start()

    def stop(self) -> None:
        """Stop the worker (if running: the thread closes the camera, when a read still in
        progress returns) or close the camera."""
        if self._worker is not None:
            if self._worker.stop():  # else still reading: a start waits for it to end
                self._worker = None
            return
        self._close()

    def _close(self) -> None:
        self.camera.close()
        self._open = False


class _InRealTime:
    """The watcher on a thread: a frame that came due while the network was still busy is
    dropped (counted in ``dropped``), never queued."""

    name = "vision"

    def __init__(self, watcher: HandWatcher) -> None:
        self.watcher = watcher

    def due_s(self) -> float:
        return self.watcher.due_s()

    def run(self, now_s: float) -> None:
        watcher = self.watcher
        watcher.run(now_s)
        late_s = watcher.clock.now() - watcher.due_s()
        if late_s > 0:
            missed = int(late_s / watcher.period_s) + 1
            watcher.dropped += missed
            watcher._next_s = watcher.due_s() + missed * watcher.period_s


def _grid(frame: Frame) -> np.ndarray:
    """The frame's grey levels averaged over a GRID of cells (float32), from every
    :data:`GRID_STRIDE`-th pixel of every :data:`GRID_STRIDE`-th row: a cell still averages
    over a hundred pixels, a quarter of a millisecond a frame where the whole frame took
    0.8 ms."""
    small = cv2.resize(frame[::GRID_STRIDE, ::GRID_STRIDE], GRID, interpolation=cv2.INTER_AREA)
    grey = cv2.cvtColor(small, cv2.COLOR_BGR2GRAY) if small.ndim == 3 else small
    return np.asarray(grey, dtype=np.float32)
