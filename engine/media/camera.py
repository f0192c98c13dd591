"""The webcam, through OpenCV: frames as BGR arrays, offline when unplugged.

:class:`OpenCvCamera` asks the camera for its size and rate, keeps OpenCV's buffer at one
frame (a worker that falls behind gets the newest frame; older ones are dropped, never
queued) and says why it failed. The worker that reads it re-opens it after a failure.
"""

from __future__ import annotations

import logging
from typing import Protocol

import cv2
import numpy as np

from engine.errors import DeviceError
from engine.media.images import Frame

log = logging.getLogger(__name__)


class CameraError(DeviceError):
    """The camera cannot be opened or stopped giving frames; the message says which."""

    def __init__(self, message: str) -> None:
        super().__init__(None, message)


class Camera(Protocol):
    """Where frames come from: a webcam, the simulated vest's camera, a video file."""

    name: str

    def open(self) -> None:
        """Start giving frames; CameraError when the camera is not there."""
        ...

    def read(self) -> Frame:
        """The next frame (waits for it, at most a frame's time or so); CameraError when
        the camera stopped giving frames (unplugged)."""
        ...

    def close(self) -> None: ...


class OpenCvCamera:
    """A V4L2 webcam (or any source OpenCV opens): ``device`` an index or a path."""

    def __init__(
        self, device: int | str, *, width: int = 640, height: int = 360, fps: float = 15.0
    ) -> None:
        self.device = device
        self.width, self.height, self.fps = width, height, fps
        self.name = f"camera {device}"
        self._capture: cv2.VideoCapture | None = None

    def open(self) -> None:
        self.close()
        capture = cv2.VideoCapture(self.device)
        if not capture.isOpened():
            capture.release()
            raise CameraError(f"{self.name}: cannot be opened (unplugged, or in use?)")
        capture.set(cv2.CAP_PROP_FRAME_WIDTH, self.width)
        capture.set(cv2.CAP_PROP_FRAME_HEIGHT, self.height)
        capture.set(cv2.CAP_PROP_FPS, self.fps)
        capture.set(cv2.CAP_PROP_BUFFERSIZE, 1)  # the newest frame, not a queue of old ones
        self._capture = capture
        got_w = int(capture.get(cv2.CAP_PROP_FRAME_WIDTH))
        got_h = int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT))
        if (got_w, got_h) != (self.width, self.height) and got_w and got_h:
            log.warning(
                "%s gives %dx%d frames, not the %dx%d asked for",
                self.name,
                got_w,
                got_h,
                self.width,
                self.height,
            )

    def read(self) -> Frame:
        if self._capture is None:
            raise CameraError(f"{self.name}: not open")
        ok, frame = self._capture.read()
        if not ok or frame is None:
            raise CameraError(f"{self.name}: gave no frame (unplugged?)")
        return np.asarray(frame, dtype=np.uint8)

    def newest(self) -> Frame:
        """The frame of this moment, not the one the camera kept since the last read (for a
        picture taken when a person asks, long after the previous one)."""
        if self._capture is not None:
            self._capture.grab()  # drops the frame held in the buffer
        return self.read()

    def close(self) -> None:
        if self._capture is not None:
            self._capture.release()
            self._capture = None
