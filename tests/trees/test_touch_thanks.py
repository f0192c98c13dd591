"""touch_thanks: a pat on the back or shoulders -> "Thank you" (paper, section 4.5.1).

A pat is a hand coming onto a pad: the touch poller sends one ``/sensors/touch/pat``
event naming the pad, however long the hand rests there."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.testing import TreeHarness

TREES = Path(__file__).resolve().parents[2] / "trees"
TREE = TREES / "touch_thanks.yaml"


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def pat(robot: TreeHarness, pad: str = "middle_back", seconds: float = 0.3) -> None:
    """A hand comes onto ``pad`` (one pat event) and rests there for ``seconds``."""
    robot.set("/sensors/touch/pat", pad)
    robot.advance(seconds)


def test_a_pat_on_the_back_is_thanked_once(robot: TreeHarness) -> None:
    pat(robot)
    robot.advance(1.0)
    assert robot.did("say") == [{"text": "Thank you", "volume": 0.8}]


def test_nobody_touching_means_nothing_is_said(robot: TreeHarness) -> None:
    assert robot.advance(5.0) == Status.FAILURE
    assert robot.said == []


def test_a_hand_resting_on_the_back_is_thanked_once_however_long_it_stays(
    robot: TreeHarness,
) -> None:
    pat(robot, seconds=10.0)  # the rest is 3 s: a resting hand is still one pat
    assert robot.said == ["Thank you"]


def test_a_pat_on_a_shoulder_is_thanked_as_one_on_the_back(robot: TreeHarness) -> None:
    pat(robot, "left_shoulder")
    assert robot.said == ["Thank you"]


def test_a_second_pat_during_the_rest_is_not_thanked_again(robot: TreeHarness) -> None:
    pat(robot)
    robot.advance(1.0)
    pat(robot)
    assert robot.said == ["Thank you"]


def test_a_pat_after_the_rest_is_thanked_again(robot: TreeHarness) -> None:
    pat(robot)
    robot.advance(3.0)
    pat(robot)
    assert robot.said == ["Thank you", "Thank you"]


def test_the_child_profile_thanks_like_a_friend_with_a_softer_voice(
    tree_harness: Callable[..., TreeHarness],
) -> None:
    robot = tree_harness(TREE, TREES / "profiles" / "child.yaml")
    pat(robot)
    assert robot.did("say") == [{"text": "Thank you, friend!", "volume": 0.6}]


def test_the_child_profile_rests_only_two_seconds_between_thanks(
    tree_harness: Callable[..., TreeHarness],
) -> None:
    robot = tree_harness(TREE, TREES / "profiles" / "child.yaml")
    pat(robot)
    robot.advance(2.0)
    pat(robot)
    assert robot.said == ["Thank you, friend!"] * 2


def test_the_adult_profile_speaks_clearly(
    tree_harness: Callable[..., TreeHarness],
) -> None:
    robot = tree_harness(TREE, TREES / "profiles" / "adult.yaml")
    pat(robot)
    assert robot.did("say") == [{"text": "Thank you", "volume": 0.9}]


def test_an_unplugged_speaker_fails_the_tree_which_rests_then_thanks_once_it_is_back(
    robot: TreeHarness,
) -> None:
    robot.services.speech.fail_next = "speaker unplugged"
    robot.set("/sensors/touch/pat", "middle_back")
    assert robot.tick() == Status.FAILURE
    assert robot.tree.root.tip().feedback_message == "could not act: speaker unplugged"
    # no second try on the next tick (that is a stutter): the tree rests as after a thanks
    robot.set("/sensors/touch/pat", "upper_back")
    assert robot.tick() == Status.FAILURE
    assert [r.action for r in robot.actions] == ["say"]
    robot.advance(3.0)  # the rest is over and the speaker is back: the next pat is thanked
    pat(robot)
    assert robot.said == ["Thank you"]
