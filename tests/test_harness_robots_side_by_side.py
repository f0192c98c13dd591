"""Each TreeHarness is a robot of its own: two run side by side in one test, and neither
sees the other's blackboard (py_trees' own blackboard is one per process; vest's nodes read
their robot's)."""

from __future__ import annotations

from pathlib import Path

from engine.testing import TreeHarness

TREES = Path(__file__).resolve().parents[1] / "trees"
TOUCH_THANKS = TREES / "touch_thanks.yaml"


def test_two_robots_run_side_by_side_and_never_see_each_other_s_keys() -> None:
    adult = TreeHarness.from_file(TOUCH_THANKS, TREES / "profiles" / "adult.yaml")
    child = TreeHarness.from_file(TOUCH_THANKS, TREES / "profiles" / "child.yaml")
    adult.set("/sensors/touch/pat", "middle_back")  # only the adult's robot is touched
    adult.advance(1.0)
    child.advance(1.0)

    assert len(adult.said) == 1
    assert child.said == []
    assert adult.get("/sensors/touch/pat") == "middle_back"
    assert child.get("/sensors/touch/pat") is None


def test_a_robot_made_later_leaves_an_earlier_one_as_it_was() -> None:
    first = TreeHarness.from_file(TOUCH_THANKS)
    first.set("/sensors/touch/pat", "middle_back")
    first.tick()
    TreeHarness.from_file(TOUCH_THANKS)  # a fresh robot: it empties only its own board
    assert first.get("/sensors/touch/pat") == "middle_back"
    first.advance(1.0)
    assert len(first.said) == 1
