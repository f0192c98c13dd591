"""hug: both side pads squeezed at once -> a pink face and "I love hugs!" (section 4.5.3)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.testing import TreeHarness

TREES = Path(__file__).resolve().parents[2] / "trees"
TREE = TREES / "hug.yaml"


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def squeeze(robot: TreeHarness, left_n: float, right_n: float, seconds: float = 2.0) -> None:
    """Both side pads pressed with these forces for ``seconds``, then let go."""
    robot.set("/sensors/force/left_n", left_n)
    robot.set("/sensors/force/right_n", right_n)
    robot.advance(seconds)
    robot.set("/sensors/force/left_n", 0.0)
    robot.set("/sensors/force/right_n", 0.0)
    robot.tick()


def test_a_hug_lights_the_face_pink_and_the_robot_says_it_loves_hugs(robot: TreeHarness) -> None:
    squeeze(robot, 6.0, 6.0)
    assert robot.did("led") == [{"color": "pink", "seconds": 2.0}]
    assert robot.did("say") == [{"text": "I love hugs!", "volume": 0.8}]


def test_a_long_hug_is_answered_once(robot: TreeHarness) -> None:
    squeeze(robot, 6.0, 6.0, seconds=5.0)
    robot.advance(2.0)
    assert robot.said == ["I love hugs!"]


@pytest.mark.parametrize(("left_n", "right_n"), [(6.0, 0.0), (0.0, 6.0), (6.0, 2.0)])
def test_pressing_one_side_only_is_not_a_hug(
    robot: TreeHarness, left_n: float, right_n: float
) -> None:
    squeeze(robot, left_n, right_n)
    assert robot.said == []
    assert robot.did("led") == []


def test_both_sides_pressed_one_after_the_other_is_not_a_hug(robot: TreeHarness) -> None:
    squeeze(robot, 6.0, 0.0)
    squeeze(robot, 0.0, 6.0)
    assert robot.said == []


def test_a_squeeze_exactly_at_the_threshold_is_not_enough(robot: TreeHarness) -> None:
    squeeze(robot, 3.0, 3.0)
    assert robot.said == []


def test_a_second_hug_during_the_rest_gets_no_second_answer(robot: TreeHarness) -> None:
    squeeze(robot, 6.0, 6.0)
    robot.advance(3.0)
    squeeze(robot, 6.0, 6.0)
    assert robot.said == ["I love hugs!"]


def test_a_hug_after_the_rest_is_answered_again(robot: TreeHarness) -> None:
    squeeze(robot, 6.0, 6.0)
    robot.advance(10.0)
    squeeze(robot, 6.0, 6.0)
    assert robot.said == ["I love hugs!", "I love hugs!"]


def test_a_gentle_child_hug_counts_with_the_child_profile(
    tree_harness: Callable[..., TreeHarness],
) -> None:
    robot = tree_harness(TREE, TREES / "profiles" / "child.yaml")
    squeeze(robot, 2.5, 2.5)
    assert robot.did("say") == [{"text": "Yay, a big hug!", "volume": 0.6}]


def test_a_gentle_hug_is_too_soft_without_a_profile(robot: TreeHarness) -> None:
    squeeze(robot, 2.5, 2.5)
    assert robot.said == []


def test_the_adult_profile_needs_a_firmer_hug_and_answers_calmly(
    tree_harness: Callable[..., TreeHarness],
) -> None:
    robot = tree_harness(TREE, TREES / "profiles" / "adult.yaml")
    squeeze(robot, 3.5, 3.5)
    assert robot.said == []
    squeeze(robot, 4.5, 4.5)
    assert robot.said == ["Thank you for the hug."]


def test_an_unplugged_speaker_fails_the_hug_after_the_face_has_lit(robot: TreeHarness) -> None:
    robot.services.speech.fail_next = "speaker unplugged"
    robot.set("/sensors/force/left_n", 6.0)
    robot.set("/sensors/force/right_n", 6.0)
    # RUNNING: the pink face still shows for its two seconds; then FAILURE, naming the speaker
    assert robot.tick() == Status.RUNNING
    assert robot.advance(2.0) == Status.FAILURE
    [failed] = robot.failed_actions
    assert (failed.action, failed.error) == ("say", "speaker unplugged")
    assert robot.did("led") == [{"color": "pink", "seconds": 2.0}]


def test_with_the_face_leds_unplugged_a_hug_is_still_answered_once_and_rests(
    robot: TreeHarness,
) -> None:
    robot.services.leds.fail_next = "LEDs unplugged"
    robot.set("/sensors/force/left_n", 6.0)
    robot.set("/sensors/force/right_n", 6.0)
    robot.advance(5.0)  # a long hug: the robot does not stutter its answer
    assert robot.said == ["I love hugs!"]
    # one try at the dark face, one answer, then the hug's rest
    assert [(r.action, r.failed) for r in robot.actions] == [("led", True), ("say", False)]
