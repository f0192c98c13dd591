"""How many fingers a hand holds up, read from its landmarks (:mod:`engine.vision.hand_landmarks`).

A finger is up when it is straight (its two joints bend less than :data:`STRAIGHT_DEG`
together), it leaves its knuckle in line with the palm (less than :data:`KNUCKLE_DEG`), and
its tip is farther from the wrist than its middle joint. The thumb is up when it is
straight at its last joint and stands away from the palm: its tip clear of the index
finger's knuckle and the middle finger's, and farther from the little finger than its own
joint. Distances are measured against the palm's length (wrist to the middle finger's
knuckle), so near and far hands, big and small, are read alike.

Only a hand *held up* is counted: its fingers pointing up, within :data:`HELD_UP_DEG` of
upright. A hand resting on a chair or hanging at someone's side is not showing a count.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

HELD_UP_DEG = 60.0
STRAIGHT_DEG = 60.0
KNUCKLE_DEG = 60.0
THUMB_STRAIGHT_DEG = 40.0
THUMB_CLEAR = 0.55
"""The thumb's tip at least this many palm lengths from the index finger's knuckle."""
FINGERS = ((5, 6, 7, 8), (9, 10, 11, 12), (13, 14, 15, 16), (17, 18, 19, 20))
"""Each finger's knuckle, joints and tip, index finger first."""
Points = npt.NDArray[np.float32]


def held_up(points: Points) -> bool:
    """Whether the hand's fingers point up (the wrist below the middle finger's knuckle,
    within :data:`HELD_UP_DEG` of upright)."""
    dx, dy = points[9, :2] - points[0, :2]
    return abs(math.degrees(math.atan2(float(dx), float(-dy)))) <= HELD_UP_DEG


def fingers_up(points: Points) -> int:
    """How many of the hand's five fingers are up (0..5)."""
    palm = _distance(points, 0, 9)
    count = 0
    for knuckle, middle, last, tip in FINGERS:
        straight = _bend(points, knuckle, middle, last) + _bend(points, middle, last, tip)
        count += (
            straight < STRAIGHT_DEG
            and _bend(points, 0, knuckle, middle) < KNUCKLE_DEG
            and _distance(points, 0, tip) > _distance(points, 0, middle)
        )
    thumb = (
        _bend(points, 2, 3, 4) < THUMB_STRAIGHT_DEG
        and _distance(points, 4, 5) > THUMB_CLEAR * palm
        and _distance(points, 4, 9) > 0.6 * palm
        and _distance(points, 4, 17) > _distance(points, 3, 17)
    )
    return count + thumb


def _distance(points: Points, a: int, b: int) -> float:
    return float(np.linalg.norm(points[a, :2] - points[b, :2]))


def _bend(points: Points, a: int, b: int, c: int) -> float:
    """How far the line a-b-c turns at b, in degrees (0: straight on), with the depth the
    landmarks carry (a finger bent towards the camera looks straight in the image)."""
    first, second = points[b] - points[a], points[c] - points[b]
    norms = float(np.linalg.norm(first) * np.linalg.norm(second))
    if norms == 0.0:
        return 180.0
    cosine = float(first @ second) / norms
    return math.degrees(math.acos(max(-1.0, min(1.0, cosine))))
