"""A hand anywhere in a camera frame, then how many fingers it holds up.

The robot's users are children standing in front of it: a hand held up at arm's length
fills a small part of a 640 x 480 frame, anywhere in it. :class:`HandFinder` finds it
first, then counts it:

1. **find**: MediaPipe's palm detector looks at the whole frame
   (:mod:`engine.vision.palm_detection`), then its hand landmark model reads the hand's 21
   landmarks (:mod:`engine.vision.hand_landmarks`). A hand that stays in view is followed
   from frame to frame through its landmarks, without the detector, until the landmark
   model no longer sees a hand there;
2. **count**: from the landmarks (:mod:`engine.vision.finger_rules`), a hand held up with
   its fingers pointing up; a hand resting or hanging down is no hand shown to the robot.

A picture smaller than the paper's 128 x 128 px window is a close-up, not a camera frame
(a photograph of a hand that fills it): the paper's network counts it, as it was trained
to (:mod:`engine.vision.classifier`). docs/vision-model-card.md gives the figures that chose
this split: at arm's length the landmarks count 94 % of one person's hands right against
63 % for the paper's network on the same hands, cut out; on close-ups the network counts
96-98 % and the detector finds few hands whose wrist the picture cuts off.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from engine.media.images import Frame
from engine.vision.classifier import HandModel, HandReading
from engine.vision.finger_rules import fingers_up, held_up
from engine.vision.hand_landmarks import LANDMARK_MODEL, Hand, HandLandmarker, Region
from engine.vision.palm_detection import PALM_MODEL, PalmDetector
from engine.vision.preprocess import fills_window

MIN_PRESENCE = 0.5
"""Below it (0..1) the landmark model does not see a hand where it looked."""
PALMS_TRIED = 2
"""Palms the detector found whose landmarks are read before deciding there is no hand."""


class HandFinder:
    """Finds and counts a hand in frames from one camera (it follows a hand from one
    frame to the next: one finder a camera). ``close_ups`` counts pictures smaller than
    its window (None: they are looked at like frames)."""

    def __init__(
        self,
        detector: PalmDetector,
        landmarker: HandLandmarker,
        *,
        close_ups: HandModel | None = None,
    ) -> None:
        self.detector, self.landmarker, self.close_ups = detector, landmarker, close_ups
        self._following: Region | None = None
        self.detections = 0
        """Frames the palm detector looked at (the others followed a hand already seen)."""

    @classmethod
    def load(
        cls,
        *,
        threads: int = 1,
        close_ups: HandModel | None = None,
        palm_model: Path = PALM_MODEL,
        landmark_model: Path = LANDMARK_MODEL,
    ) -> HandFinder:
        """The project's models (ConfigError naming a file that is missing or broken)."""
        return cls(
            PalmDetector(palm_model, threads=threads),
            HandLandmarker(landmark_model, threads=threads),
            close_ups=close_ups,
        )

    def forget(self) -> None:
        """Stop following a hand (the next frame is looked at whole)."""
        self._following = None

    def read(self, frame: Frame) -> HandReading:
        """What ``frame`` (BGR, as cameras and OpenCV give it) shows: no hand held up, a
        hand whose count is not sure, or its count; with the hand's box (px)."""
        if self.close_ups is not None and not fills_window(frame, self.close_ups.settings):
            reading = self.close_ups.read(frame)
            height, width = frame.shape[:2]
            return HandReading(
                reading.fingers,
                reading.confidence,
                reading.probabilities,
                True,
                (0, 0, width, height),
            )
        rgb = np.asarray(cv2.cvtColor(frame, cv2.COLOR_BGR2RGB), dtype=np.uint8)
        hand = self._find(rgb)
        if hand is None:
            return HandReading(None, 0.0, (), False, None)
        if not held_up(hand.points):  # resting, hanging down: not shown to the robot
            return HandReading(None, hand.presence, (), False, None)
        return HandReading(fingers_up(hand.points), hand.presence, (), True, hand.box())

    def _find(self, rgb: Frame) -> Hand | None:
        """The hand followed from the last frame, else the best one the detector finds."""
        if self._following is not None:
            hand = self.landmarker.landmarks(rgb, self._following)
            if hand.presence >= MIN_PRESENCE:
                self._following = Region.of_landmarks(hand.points)
                return hand
            self._following = None
        self.detections += 1
        for palm in self.detector.find(rgb)[:PALMS_TRIED]:
            hand = self.landmarker.landmarks(rgb, Region.of_palm(palm))
            if hand.presence >= MIN_PRESENCE:
                self._following = Region.of_landmarks(hand.points)
                return hand
        return None
