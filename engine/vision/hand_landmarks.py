"""The 21 landmarks of a hand (wrist, knuckles, joints, fingertips): MediaPipe's hand
landmark model on ONNX Runtime.

The model (``models/hand_landmarks.onnx``, MediaPipe's "full" hand landmark model,
Apache-2.0, converted by ``scripts/convert-hand-models``) reads a 224 x 224 px square of
the frame turned so the hand stands upright: its region (:class:`Region`) comes from a
palm the detector found, or from the hand's landmarks in the frame before (a hand that
stays in view is followed without the detector, as MediaPipe does). It answers the
landmarks, which come back in the frame's pixels, and how sure it is a hand is there.

Landmarks are numbered as MediaPipe numbers them: 0 the wrist; 1-4 the thumb (4 its tip);
5-8 the index finger (5 its knuckle, 6 and 7 its joints, 8 its tip); 9-12 the middle
finger; 13-16 the ring finger; 17-20 the little finger.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from engine.media.images import Frame
from engine.vision.onnx_session import onnx_session
from engine.vision.palm_detection import Palm, upright_angle

LANDMARK_MODEL = Path(__file__).resolve().parent / "models" / "hand_landmarks.onnx"
INPUT_PX = 224
PALM_SCALE, PALM_SHIFT = 2.6, -0.5
"""From a palm's box to the hand's square: 2.6 times as big, moved half a box towards the
fingers (MediaPipe's values)."""
LANDMARKS_SCALE = 2.0
"""From the landmarks' extent (wrist to knuckles) to the next frame's square."""
Points = npt.NDArray[np.float32]


@dataclass(frozen=True)
class Region:
    """A square of the frame around a hand: its centre and side (px) and how far it is
    turned (radians; 0: fingers up)."""

    centre_x: float
    centre_y: float
    side: float
    angle: float

    @classmethod
    def of_palm(cls, palm: Palm) -> Region:
        angle = palm.angle
        shift_x, shift_y = 0.0, PALM_SHIFT * palm.height
        centre_x = palm.centre_x + shift_x * math.cos(angle) - shift_y * math.sin(angle)
        centre_y = palm.centre_y + shift_x * math.sin(angle) + shift_y * math.cos(angle)
        return cls(centre_x, centre_y, max(palm.width, palm.height) * PALM_SCALE, angle)

    @classmethod
    def of_landmarks(cls, points: Points) -> Region:
        """The square to look in next, from the landmarks of the hand seen now."""
        angle = upright_angle(points[0, :2], points[9, :2])
        palm = points[[0, 1, 2, 3, 5, 6, 9, 10, 13, 14, 17, 18], :2]
        cos, sin = math.cos(angle), math.sin(angle)
        turned = palm @ np.asarray([[cos, -sin], [sin, cos]], np.float32)  # upright
        low, high = turned.min(0), turned.max(0)
        middle = (low + high) / 2
        side = float(max(high - low)) * LANDMARKS_SCALE
        centre = middle @ np.asarray([[cos, sin], [-sin, cos]], np.float32)
        centre_y = float(centre[1]) - 0.1 * side * math.cos(angle)
        centre_x = float(centre[0]) + 0.1 * side * math.sin(angle)
        return cls(centre_x, centre_y, side, angle)

    def box(self) -> tuple[int, int, int, int]:
        """The square's upright bounding box in the frame: (x, y, width, height) px."""
        reach = self.side / 2 * (abs(math.cos(self.angle)) + abs(math.sin(self.angle)))
        return (
            round(self.centre_x - reach),
            round(self.centre_y - reach),
            round(2 * reach),
            round(2 * reach),
        )


@dataclass(frozen=True)
class Hand:
    """A hand's landmarks in the frame (21 rows of x, y px and a depth in px relative to
    the wrist) and how sure the model is that they are a hand's (0..1)."""

    points: Points
    presence: float

    def box(self) -> tuple[int, int, int, int]:
        """The landmarks' bounding box: (x, y, width, height) px."""
        low, high = self.points[:, :2].min(0), self.points[:, :2].max(0)
        return (round(low[0]), round(low[1]), round(high[0] - low[0]), round(high[1] - low[1]))


class HandLandmarker:
    """The hand landmark model, loaded once; :meth:`landmarks` is called from the vision
    worker."""

    def __init__(self, path: Path = LANDMARK_MODEL, *, threads: int = 1) -> None:
        self.session = onnx_session(path, threads=threads)
        self.input_name = self.session.get_inputs()[0].name

    def landmarks(self, rgb: Frame, region: Region) -> Hand:
        """The hand in ``region`` of ``rgb`` (an RGB frame)."""
        scale = region.side / INPUT_PX
        cos, sin = math.cos(region.angle), math.sin(region.angle)
        half = INPUT_PX / 2
        # the square's pixel (u, v) comes from the frame's (x, y) = this matrix @ (u, v, 1)
        to_frame = np.asarray(
            [
                [scale * cos, -scale * sin, region.centre_x - scale * half * (cos - sin)],
                [scale * sin, scale * cos, region.centre_y - scale * half * (sin + cos)],
            ],
            np.float32,
        )
        square = cv2.warpAffine(
            rgb,
            to_frame,
            (INPUT_PX, INPUT_PX),
            flags=cv2.WARP_INVERSE_MAP | cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_CONSTANT,
        )
        tensor = (square.astype(np.float32) / 255.0)[np.newaxis]
        outputs = self.session.run(None, {self.input_name: tensor})
        raw = np.asarray(outputs[0], np.float32).reshape(21, 3)
        presence = float(np.asarray(outputs[1]).ravel()[0])
        x = to_frame[0, 0] * raw[:, 0] + to_frame[0, 1] * raw[:, 1] + to_frame[0, 2]
        y = to_frame[1, 0] * raw[:, 0] + to_frame[1, 1] * raw[:, 1] + to_frame[1, 2]
        points = np.stack([x, y, raw[:, 2] * scale], axis=1).astype(np.float32)
        return Hand(points, presence)
