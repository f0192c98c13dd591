"""finger_game: a child holds up a hand, the robot asks for three, two, then five fingers;
praise and a green face when the count is right, a gentle hint and a second try when not."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from engine.testing import TreeHarness

TREE = Path(__file__).resolve().parents[2] / "trees" / "finger_game.yaml"
SHOWN = "/vision/hand/shown"


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def show(robot: TreeHarness, fingers: int, *, then_wait_s: float = 6.0) -> None:
    """The vision worker saw a steady count; the robot gets time to answer."""
    robot.set(SHOWN, fingers)
    robot.set("/vision/hand/held", fingers)
    robot.advance(then_wait_s)


def test_a_hand_held_up_starts_the_game_and_a_right_count_is_praised(robot: TreeHarness) -> None:
    robot.advance(1.0)
    assert robot.said == []  # nobody is playing yet

    show(robot, 5)
    assert robot.said == ["Let's play a counting game!", "Show me three fingers!"]

    show(robot, 3)
    assert robot.said[2:] == ["Yes! That's three. Well done!", "Show me two fingers!"]
    assert {"color": "green", "seconds": 2.0} in robot.did("led")


def test_a_wrong_count_gets_a_gentle_hint_and_another_try(robot: TreeHarness) -> None:
    show(robot, 5)
    show(robot, 4)
    assert robot.said[-1] == "Almost! Let's count together: one, two, three. Show me three."
    assert {"color": "orange", "seconds": 2.0} in robot.did("led")

    show(robot, 3)
    assert "Yes! That's three. Well done!" in robot.said


def test_two_wrong_tries_end_the_round_kindly_and_the_game_goes_on(robot: TreeHarness) -> None:
    show(robot, 5)
    show(robot, 4)
    show(robot, 1)
    assert robot.said[-2:] == [
        "Good try! We'll count three together another time.",
        "Show me two fingers!",
    ]
    robot.advance(20.0)  # nothing more shown: the round for two ends too, and the next begins
    assert robot.said.count("Show me three fingers!") == 1
    assert robot.said[-2:] == [
        "Good try! We'll count two together another time.",
        "Show me five fingers!",
    ]


def test_a_child_already_showing_the_count_is_praised_at_once(robot: TreeHarness) -> None:
    show(robot, 3)  # holds up three before being asked, and keeps it up
    assert robot.said[:3] == [
        "Let's play a counting game!",
        "Show me three fingers!",
        "Yes! That's three. Well done!",
    ]


def test_no_answer_is_asked_again_and_then_let_go(robot: TreeHarness) -> None:
    show(robot, 5)
    robot.advance(20.0)  # two tries of 8 s pass with no hand shown
    assert "Good try! We'll count three together another time." in robot.said
    assert not any(line.startswith("Almost") for line in robot.said)


def test_a_whole_game_ends_with_thanks_then_rests(robot: TreeHarness) -> None:
    show(robot, 5)
    for fingers in (3, 2, 5):
        show(robot, fingers)
    assert robot.said[-1] == "You counted so well. Thank you for playing!"
    praised = [line for line in robot.said if line.startswith("Yes!")]
    assert len(praised) == 3

    show(robot, 4)  # straight after the game: the robot rests
    assert robot.said[-1] == "You counted so well. Thank you for playing!"
