"""The hand finder: a hand held up at arm's length, anywhere in a webcam frame, found and
counted; a frame with no hand held up never gets a count; a hand that stays in view is
followed without the palm detector; a close-up is counted by the paper's network.

The frames are real (examples/hands-arms-length: one person, CC BY-SA 4.0); the finder was
not made from them (MediaPipe's models, generic counting rules). bench/bench_vision.py
gives the figures on all 500 frames of that person.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine.media.images import read_image
from engine.vision.classifier import HandModel
from engine.vision.hand_finder import HandFinder
from engine.vision.palm_detection import anchors

pytestmark = pytest.mark.models

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ARMS_LENGTH = EXAMPLES / "hands-arms-length"


@pytest.fixture(scope="module")
def finder() -> HandFinder:
    return HandFinder.load(close_ups=HandModel.load())


def test_hands_held_up_at_arm_s_length_are_counted(finder: HandFinder) -> None:
    right = wrong = missed = 0
    for count in range(1, 6):
        for path in sorted((ARMS_LENGTH / str(count)).glob("*.jpg")):
            finder.forget()
            reading = finder.read(read_image(path))
            if not reading.present or reading.fingers is None:
                missed += 1
            elif reading.fingers == count:
                right += 1
            else:
                wrong += 1
    assert right + wrong + missed == 100
    assert right >= 90, (right, wrong, missed)  # 93 when this was written


def test_a_frame_with_no_hand_held_up_never_gets_a_count(finder: HandFinder) -> None:
    """Empty rooms, and two where a hand rests on a chair or hangs at someone's side."""
    for path in sorted((ARMS_LENGTH / "none").glob("*.jpg")):
        finder.forget()
        reading = finder.read(read_image(path))
        assert (reading.present, reading.fingers, reading.box) == (False, None, None), path.name


def test_a_hand_that_stays_in_view_is_followed_without_the_detector(finder: HandFinder) -> None:
    frame = read_image(ARMS_LENGTH / "4" / "four_12.jpg")
    finder.forget()
    before = finder.detections
    readings = [finder.read(frame) for _ in range(10)]
    assert finder.detections == before + 1  # found once, then followed by its landmarks
    assert {r.fingers for r in readings} == {4}
    room = read_image(ARMS_LENGTH / "none" / "office_10.jpg")
    assert not finder.read(room).present  # gone: the next frame is looked at whole again
    assert finder.read(frame).fingers == 4 and finder.detections == before + 3


def test_the_box_is_where_the_hand_is(finder: HandFinder) -> None:
    frame = read_image(ARMS_LENGTH / "2" / "two_106.jpg")
    finder.forget()
    reading = finder.read(frame)
    assert reading.box is not None
    x, y = reading.box[:2]
    moved = np.zeros((480 + 100, 640 + 200, 3), np.uint8)
    moved[100:, 200:] = frame  # the same hand, 200 px right and 100 px down
    finder.forget()
    again = finder.read(moved)
    assert again.fingers == 2 and again.box is not None
    assert abs(again.box[0] - (x + 200)) <= 8 and abs(again.box[1] - (y + 100)) <= 8


def test_a_close_up_is_counted_by_the_paper_s_network(finder: HandFinder) -> None:
    photo = next((EXAMPLES / "hands-real" / "held-out" / "5").glob("*.jpg"))
    reading = finder.read(read_image(photo))
    assert reading.present and reading.fingers == 5 and len(reading.probabilities) == 6


def test_the_palm_detector_s_anchors_are_mediapipe_s() -> None:
    centres = anchors()
    assert centres.shape == (2016, 2)  # 24 x 24 x 2 at stride 8, then 12 x 12 x 6
    assert np.allclose(centres[0], (0.5 / 24, 0.5 / 24))
    assert np.allclose(centres[-1], (11.5 / 12, 11.5 / 12))
