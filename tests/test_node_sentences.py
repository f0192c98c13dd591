"""A leaf said in words a person reads, in the editor's outline and the drawings: the
question a Check asks with its key's own words and unit, what an action does."""

from __future__ import annotations

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.loader.node_sentences import node_sentence

CATALOGUE = default_catalogue()


@pytest.mark.parametrize(
    ("type_name", "args", "said"),
    [
        (
            "Check",
            {"key": "/sensors/force/left_n", "above": 5.0},
            "force on the left side pad above 5 N?",
        ),
        (  # the live view is told every parameter, those not given as None
            "Check",
            {"key": "/sensors/force/left_n", "above": None, "below": 2.0, "equals": None},
            "force on the left side pad below 2 N?",
        ),
        (
            "Check",
            {"key": "/sensors/force/left_n", "above": "${hug_threshold_n}"},
            "force on the left side pad above hug_threshold_n N?",
        ),
        (
            "Check",
            {"key": "/sensors/range/center_mm", "between": [100, 300]},
            "between 100 and 300 mm?",
        ),
        ("Check", {"key": "/vars/game/score", "equals": 3}, "the variable game/score is 3?"),
        (
            "OnTouch",
            {"pads": ["left_shoulder", "right_shoulder"]},
            "a pat on left_shoulder, right_shoulder?",
        ),
        ("OnTouch", {}, "a pat?"),
        ("Check", {"key": "/sensors/touch/any", "equals": True}, "any pad is touched?"),
        ("Check", {"key": "/sensors/touch/any", "equals": False}, "not: any pad is touched?"),
        (
            "OnEvent",
            {"key": "/sensors/gesture/last", "equals": "wave"},
            "new: a hand gesture: wave?",
        ),
        ("Say", {"text": "Thank you"}, "say \u201cThank you\u201d"),
        ("SetLed", {"color": "pink", "seconds": 2.0}, "light the face pink for 2 s"),
        ("SetLed", {"color": "off"}, "turn the face lights off"),
        (
            "MoveServo",
            {"joint": "left_arm", "angle_deg": 45, "speed_dps": 60},
            "turn left_arm to 45 deg at 60 deg/s",
        ),
        ("Wait", {"seconds": 1.5}, "wait 1.5 s"),
    ],
)
def test_a_leaf_is_said_in_words(type_name: str, args: dict[str, object], said: str) -> None:
    sentence = node_sentence(type_name, args, CATALOGUE)
    assert sentence is not None and said in sentence


def test_a_node_type_it_does_not_know_is_left_to_its_type_and_parameters() -> None:
    assert node_sentence("Blink", {"times": 3}, CATALOGUE) is None
    assert node_sentence("Sequence", {}, CATALOGUE) is None


def test_the_live_view_is_told_each_node_in_words_beside_its_parameters() -> None:
    from pathlib import Path

    from engine.runtime.tree_watch import TreeWatch
    from engine.testing import TreeHarness

    hug = TreeHarness.from_file(Path(__file__).resolve().parents[1] / "trees" / "hug.yaml")
    watched = TreeWatch().watch(hug.running)
    check = watched.info[1]
    assert check.label == "Check key=/sensors/force/left_n above=3.0"  # for engineers
    assert check.words == "force on the left side pad above 3 N?"  # for people
