"""The simulated vest's webcam: frames of the simulated world, at the camera's size.

What the scenario holds in front of it (``show_hand``) becomes frames the same hand
finder reads: a person holding up 1..5 fingers at arm's length (a real webcam frame of
``examples/hands-arms-length``, picked by the event), a picture file, or a video file
played from when it was shown, on the robot's clock. A picture is seen whole (scaled down
to the frame when it is bigger), or held up at a distance (``at`` and ``width_px``: where
in the frame, and how big); a picture smaller than the paper's window is a close-up,
filling the window. With nothing shown, the camera sees the empty room.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2
import numpy as np

from engine.clock import Clock
from engine.media.camera import CameraError
from engine.media.images import Frame, read_image
from engine.scenario.world import ShownHand, World
from engine.vision.preprocess import SIDE_PX, Preprocessing, filling, fills_window
from engine.vision_training.shown_hand import render_shown_hand
from engine.vision_training.synthetic_hands import render_frame

ARMS_LENGTH = Path(__file__).resolve().parents[2] / "examples" / "hands-arms-length"
"""Real webcam frames of a person holding up 1..5 fingers at arm's length (CC BY-SA 4.0)."""


def arms_length_frame(fingers: int, seed: int) -> Path | None:
    """One of the frames of a person holding up ``fingers`` (1..5), by ``seed``; None when
    there are none (0 fingers, or the examples are not installed)."""
    frames = sorted((ARMS_LENGTH / str(fingers)).glob("*.jpg")) if fingers else []
    return frames[seed % len(frames)] if frames else None


class SimulatedCamera:
    """A camera of ``width`` x ``height`` px looking at ``world``. A world listener: the
    event ``unplug`` ``{device: <its name>, seconds}`` (or :meth:`unplug`) makes it fail
    like a webcam pulled out (:class:`CameraError`) for that long."""

    def __init__(
        self,
        world: World,
        clock: Clock,
        *,
        width: int = 640,
        height: int = 360,
        window: tuple[int, int] | None = None,
        name: str = "camera",
    ) -> None:
        self.world, self.clock = world, clock
        self.width, self.height, self.window = width, height, window
        self.name = name
        self._unplugged_until_s = float("-inf")
        self._open = False
        self._shown: ShownHand | None = None
        self._shown_before: ShownHand | None = None
        self._shown_at_s = 0.0
        self._still: Frame | None = None
        self._video: cv2.VideoCapture | None = None
        self._room = render_frame(None, np.random.default_rng(0), width_px=width, height_px=height)
        self.frames_given = 0

    @property
    def unplugged(self) -> bool:
        return self.clock.now() < self._unplugged_until_s

    def unplug(self, seconds: float) -> None:
        """Pull the camera out for ``seconds`` (clock seconds)."""
        self._unplugged_until_s = self.clock.now() + seconds

    def world_changed(self, world: World, what: str) -> None:
        """The camera looks at the world when it reads a frame: nothing to do here."""

    def world_event(self, kind: str, value: Any) -> None:
        named = isinstance(value, dict) and value.get("device") == self.name
        if kind in ("unplug", "fault") and named:
            self.unplug(float(value.get("seconds", 0.0)))

    def open(self) -> None:
        if self.unplugged:
            raise CameraError(f"{self.name}: cannot be opened (unplugged)")
        self._open = True

    def read(self) -> Frame:
        if self.unplugged or not self._open:
            self._open = False
            raise CameraError(f"{self.name}: gave no frame (unplugged?)")
        hand = self.world.hand
        if hand is not self._shown:
            self._show(hand)
        self.frames_given += 1
        if self._video is not None:
            return self._video_frame()
        return self._still if self._still is not None else self._room

    def close(self) -> None:
        self._open = False
        self._release_video()
        self._shown = None  # opened again, it looks afresh (a video resumes where it is)

    def _show(self, hand: ShownHand | None) -> None:
        if hand is not self._shown_before:  # held up now, not the same one looked at again
            self._shown_at_s = self.clock.now()
        self._shown = self._shown_before = hand
        self._still = None
        self._release_video()
        if hand is None:
            return
        if hand.video is not None:
            self._video = cv2.VideoCapture(hand.video)
            self._video_index = -1
            self._video_frame_last: Frame = self._room
        elif hand.image is not None:
            self._still = self._fit(read_image(Path(hand.image)), hand.at, hand.width_px)
        elif hand.fingers is not None:  # (no fingers, no picture: the empty room)
            frame = arms_length_frame(hand.fingers, hand.seed)
            if frame is not None:
                self._still = self._fit(read_image(frame))
                return
            rng = np.random.default_rng(hand.seed)  # a closed hand, drawn
            self._still = render_shown_hand(
                hand.fingers, rng, width_px=self.width, height_px=self.height, window=self.window
            )

    def _fit(
        self, image: Frame, at: tuple[int, int] | None = None, width_px: int | None = None
    ) -> Frame:
        """A picture in the camera's frame: held ``at`` a place scaled to ``width_px``;
        else seen whole, centred on the room (scaled down to fit when it is bigger than
        the frame). A picture smaller than the crop window (a 100 x 100 px photograph of a
        hand) is held up close: its centred square scaled to fill the window, where the
        window is (as `vest gesture` reads it)."""
        frame = self._room.copy()
        if at is not None and width_px is not None:
            height_px = max(1, round(image.shape[0] * width_px / image.shape[1]))
            scaled = cv2.resize(image, (width_px, height_px), interpolation=cv2.INTER_AREA)
            x, y = at
            cut = scaled[: max(0, self.height - y), : max(0, self.width - x)]
            frame[y : y + cut.shape[0], x : x + cut.shape[1]] = cut
            return frame
        if not fills_window(image, Preprocessing()):
            x, y = self.window or ((self.width - SIDE_PX) // 2, (self.height - SIDE_PX) // 2)
            frame[y : y + SIDE_PX, x : x + SIDE_PX] = filling(image, Preprocessing())
            return frame
        height, width = image.shape[:2]
        shrink = min(1.0, self.width / width, self.height / height)
        if shrink < 1.0:
            size = (max(1, round(width * shrink)), max(1, round(height * shrink)))
            image = np.asarray(cv2.resize(image, size, interpolation=cv2.INTER_AREA), np.uint8)
            height, width = image.shape[:2]
        y, x = (self.height - height) // 2, (self.width - width) // 2
        frame[y : y + height, x : x + width] = image
        return frame

    def _video_frame(self) -> Frame:
        """The video's frame for the time since it was shown; its last frame once it ended."""
        assert self._video is not None
        rate = self._video.get(cv2.CAP_PROP_FPS) or 25.0
        wanted = int((self.clock.now() - self._shown_at_s) * rate)
        while self._video_index < wanted:
            ok, frame = self._video.read()
            if not ok:
                break
            self._video_index += 1
            self._video_frame_last = self._fit(np.asarray(frame, dtype=np.uint8))
        return self._video_frame_last

    def _release_video(self) -> None:
        if self._video is not None:
            self._video.release()
            self._video = None
