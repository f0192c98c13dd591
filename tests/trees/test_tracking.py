"""tracking: turn the neck toward the nearest of three distances (paper, section 4.5.4)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.testing import TreeHarness

TREE = Path(__file__).resolve().parents[2] / "trees" / "tracking.yaml"
LEFT = {"joint": "neck", "angle_deg": 30.0, "speed_dps": 90.0}
RIGHT = {"joint": "neck", "angle_deg": -30.0, "speed_dps": 90.0}


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def see(
    robot: TreeHarness,
    left: float | None = None,
    center: float | None = None,
    right: float | None = None,
) -> None:
    """What the three time-of-flight sensors read, in mm (None: nothing in range)."""
    robot.set("/sensors/range/left_mm", left)
    robot.set("/sensors/range/center_mm", center)
    robot.set("/sensors/range/right_mm", right)


def test_someone_nearest_on_the_left_turns_the_neck_left(robot: TreeHarness) -> None:
    see(robot, left=250, center=600, right=900)
    robot.advance(1.0)
    assert robot.did("servo") == [LEFT]


def test_someone_nearest_on_the_right_turns_the_neck_right(robot: TreeHarness) -> None:
    see(robot, left=900, center=600, right=250)
    robot.advance(1.0)
    assert robot.did("servo") == [RIGHT]


def test_someone_straight_ahead_needs_no_turn(robot: TreeHarness) -> None:
    see(robot, left=900, center=250, right=600)
    assert robot.advance(1.0) == Status.SUCCESS
    assert robot.did("servo") == []


def test_nothing_in_range_means_no_move(robot: TreeHarness) -> None:
    assert robot.advance(1.0) == Status.SUCCESS
    assert robot.did("servo") == []


def test_things_farther_than_max_mm_are_ignored(robot: TreeHarness) -> None:
    see(robot, left=1500, center=None, right=None)
    robot.advance(1.0)
    assert robot.did("servo") == []


def test_the_neck_turns_once_while_the_person_stays_on_the_same_side(robot: TreeHarness) -> None:
    see(robot, left=250, center=600, right=900)
    robot.advance(2.0)
    see(robot, left=300, center=700, right=900)  # moved a little, still on the left
    robot.advance(2.0)
    assert robot.did("servo") == [LEFT]


def test_the_neck_follows_a_person_from_left_to_right(robot: TreeHarness) -> None:
    see(robot, left=250, center=600, right=900)
    robot.advance(1.0)
    see(robot, left=900, center=600, right=250)
    robot.advance(1.0)
    assert robot.did("servo") == [LEFT, RIGHT]


def test_a_person_stepping_in_front_does_not_turn_the_neck_back(robot: TreeHarness) -> None:
    see(robot, left=250, center=600, right=900)
    robot.advance(1.0)
    see(robot, left=900, center=250, right=900)
    robot.advance(1.0)
    assert robot.did("servo") == [LEFT]


def test_a_failed_turn_fails_the_tree_and_is_tried_again(robot: TreeHarness) -> None:
    robot.services.servos.fail_next = "neck servo stalled"
    see(robot, left=250, center=600, right=900)
    assert robot.tick() == Status.FAILURE
    robot.advance(1.0)
    # the stalled turn is a failed call, not a turn; the retry is the turn
    assert [record.args for record in robot.failed_actions] == [LEFT]
    assert robot.did("servo") == [LEFT]
