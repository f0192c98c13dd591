"""wave_greeting: a wave in front of the gesture sensor -> "Hello" (paper, section 4.5.2)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.testing import TreeHarness

TREES = Path(__file__).resolve().parents[2] / "trees"
TREE = TREES / "wave_greeting.yaml"


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def test_a_wave_is_greeted_with_hello_and_a_green_face(robot: TreeHarness) -> None:
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(1.0)
    assert robot.did("say") == [{"text": "Hello", "volume": 0.8}]
    assert robot.did("led") == [{"color": "green", "seconds": 1.0}]


def test_one_wave_is_greeted_once_although_it_stays_on_the_blackboard(
    robot: TreeHarness,
) -> None:
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(10.0)  # far longer than the 2 s rest
    assert robot.get("/sensors/gesture/last") == "wave"
    assert robot.said == ["Hello"]


@pytest.mark.parametrize("gesture", ["swipe_left", "swipe_right"])
def test_a_swipe_is_greeted_too(robot: TreeHarness, gesture: str) -> None:
    robot.set("/sensors/gesture/last", gesture)
    robot.advance(1.0)
    assert robot.said == ["Hello"]


@pytest.mark.parametrize("gesture", ["hover", "swipe_up"])
def test_other_gestures_are_not_greeted(robot: TreeHarness, gesture: str) -> None:
    robot.set("/sensors/gesture/last", gesture)
    robot.advance(1.0)
    assert robot.said == []


def test_waving_again_during_the_rest_gets_no_second_hello(robot: TreeHarness) -> None:
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(1.5)
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(5.0)
    assert robot.said == ["Hello"]


def test_a_wave_after_the_rest_is_greeted_again(robot: TreeHarness) -> None:
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(4.0)
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(1.0)
    assert robot.said == ["Hello", "Hello"]


@pytest.mark.parametrize(
    ("profile", "greeting"),
    [
        ("child", {"text": "Hi there!", "volume": 0.6}),
        ("adult", {"text": "Hello, nice to see you.", "volume": 0.9}),
    ],
)
def test_the_profile_chooses_the_greeting(
    tree_harness: Callable[..., TreeHarness], profile: str, greeting: dict[str, object]
) -> None:
    robot = tree_harness(TREE, TREES / "profiles" / f"{profile}.yaml")
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(1.0)
    assert robot.did("say") == [greeting]


def test_an_unplugged_speaker_fails_the_greeting(robot: TreeHarness) -> None:
    robot.services.speech.fail_next = "speaker unplugged"
    robot.set("/sensors/gesture/last", "wave")
    assert robot.tick() == Status.RUNNING  # the green light still shows for its second
    assert robot.advance(1.0) == Status.FAILURE
