"""Where a hand is in a whole camera frame: MediaPipe's palm detector on ONNX Runtime.

The model (``models/palm_detection.onnx``, MediaPipe's "full" palm detector, Apache-2.0,
converted by ``scripts/convert-hand-models``) reads the frame letterboxed to 192 x 192 px
and scores 2,016 anchors (SSD-style, strides 8, 16, 16, 16): each a palm box and seven
keypoints (the wrist first, the middle finger's knuckle third). Boxes that overlap are
merged, weighted by their scores, as MediaPipe does; what comes back is in the frame's
own pixels.
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

PALM_MODEL = Path(__file__).resolve().parent / "models" / "palm_detection.onnx"
INPUT_PX = 192
STRIDES = (8, 16, 16, 16)
MIN_SCORE = 0.5
"""A palm below this score (0..1) is not one."""
MERGE_IOU = 0.3
Points = npt.NDArray[np.float32]


@dataclass(frozen=True)
class Palm:
    """A palm found in a frame: its ``score`` (0..1), its box's centre and size (px) and
    seven keypoints (px, as (x, y) rows: 0 the wrist, 2 the middle finger's knuckle)."""

    score: float
    centre_x: float
    centre_y: float
    width: float
    height: float
    keypoints: Points

    @property
    def angle(self) -> float:
        """How far the hand leans from upright (radians; 0: fingers up, clockwise positive),
        from the wrist to the middle finger's knuckle."""
        wrist, knuckle = self.keypoints[0], self.keypoints[2]
        return upright_angle(wrist, knuckle)


def upright_angle(wrist: Points, knuckle: Points) -> float:
    """The angle (radians) of the line from ``wrist`` to ``knuckle`` from straight up."""
    return math.atan2(float(knuckle[0] - wrist[0]), float(wrist[1] - knuckle[1]))


def anchors() -> Points:
    """The detector's anchor centres (x, y as fractions of its input), in its output order."""
    centres: list[tuple[float, float]] = []
    layer = 0
    while layer < len(STRIDES):
        same = layer
        while same < len(STRIDES) and STRIDES[same] == STRIDES[layer]:
            same += 1
        per_cell = 2 * (same - layer)
        cells = math.ceil(INPUT_PX / STRIDES[layer])
        for y in range(cells):
            for x in range(cells):
                centres += [((x + 0.5) / cells, (y + 0.5) / cells)] * per_cell
        layer = same
    return np.asarray(centres, dtype=np.float32)


class PalmDetector:
    """The palm detector, loaded once; :meth:`find` is called from the vision worker."""

    def __init__(self, path: Path = PALM_MODEL, *, threads: int = 1) -> None:
        self.session = onnx_session(path, threads=threads)
        self.input_name = self.session.get_inputs()[0].name
        self.anchors = anchors()

    def find(self, rgb: Frame, min_score: float = MIN_SCORE) -> list[Palm]:
        """The palms in ``rgb`` (an RGB frame), best first."""
        height, width = rgb.shape[:2]
        side = max(height, width)
        top, left = (side - height) // 2, (side - width) // 2
        square = np.zeros((side, side, 3), np.uint8)
        square[top : top + height, left : left + width] = rgb
        small = cv2.resize(square, (INPUT_PX, INPUT_PX), interpolation=cv2.INTER_AREA)
        tensor = (small.astype(np.float32) / 255.0)[np.newaxis]
        boxes, logits = self.session.run(None, {self.input_name: tensor})
        scores = 1.0 / (1.0 + np.exp(-np.clip(logits[0, :, 0], -80.0, 80.0)))
        kept = np.flatnonzero(scores >= min_score)
        if kept.size == 0:
            return []
        raw = boxes[0, kept].astype(np.float32) / INPUT_PX
        centres = raw[:, :2] + self.anchors[kept]
        sizes = raw[:, 2:4]
        points = raw[:, 4:].reshape(-1, 7, 2) + self.anchors[kept][:, np.newaxis, :]
        palms = []
        for group, weights in _merged(centres, sizes, scores[kept]):
            total = float(weights.sum())
            centre = (centres[group] * weights[:, None]).sum(0) / total
            size = (sizes[group] * weights[:, None]).sum(0) / total
            keypoints = (points[group] * weights[:, None, None]).sum(0) / total
            shift = np.asarray([left, top], np.float32)
            palms.append(
                Palm(
                    float(weights.max()),
                    float(centre[0] * side - left),
                    float(centre[1] * side - top),
                    float(size[0] * side),
                    float(size[1] * side),
                    (keypoints * side - shift).astype(np.float32),
                )
            )
        return palms


def _merged(
    centres: Points, sizes: Points, scores: npt.NDArray[np.float32]
) -> list[tuple[npt.NDArray[np.intp], npt.NDArray[np.float32]]]:
    """Groups of overlapping boxes (IoU above :data:`MERGE_IOU` with the best one left),
    best first: each group's members and their scores (MediaPipe's weighted merge)."""
    low, high = centres - sizes / 2, centres + sizes / 2
    area = sizes[:, 0] * sizes[:, 1]
    left = np.argsort(-scores)
    groups = []
    while left.size:
        best = left[0]
        overlap = np.clip(
            np.minimum(high[best], high[left]) - np.maximum(low[best], low[left]), 0.0, None
        )
        inter = overlap[:, 0] * overlap[:, 1]
        iou = inter / (area[best] + area[left] - inter + 1e-9)
        members = left[iou > MERGE_IOU]
        groups.append((members, scores[members]))
        left = left[iou <= MERGE_IOU]
    return groups
