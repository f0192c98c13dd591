"""py_trees' blackboard is process-wide, so TreeHarness works one at a time.

A second harness resets the blackboard the first one used; the first then refuses to go
on, saying why, instead of silently reading the second one's values.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.testing import HarnessReplacedError, TreeHarness

TREES = Path(__file__).resolve().parents[1] / "trees"
TOUCH_THANKS = TREES / "touch_thanks.yaml"


def test_an_older_harness_refuses_to_tick_after_a_newer_one_was_created() -> None:
    adult = TreeHarness.from_file(TOUCH_THANKS, TREES / "profiles" / "adult.yaml")
    TreeHarness.from_file(TOUCH_THANKS, TREES / "profiles" / "child.yaml")

    with pytest.raises(HarnessReplacedError, match="py_trees' blackboard is process-wide"):
        adult.tick()


def test_an_older_harness_refuses_to_be_set_after_a_newer_one_was_created() -> None:
    adult = TreeHarness.from_file(TOUCH_THANKS)
    TreeHarness.from_file(TOUCH_THANKS)

    with pytest.raises(HarnessReplacedError, match="used after another TreeHarness was created"):
        adult.set("/sensors/touch/pat", "middle_back")


def test_two_robots_are_compared_one_after_the_other() -> None:
    adult = TreeHarness.from_file(TOUCH_THANKS, TREES / "profiles" / "adult.yaml")
    adult.set("/sensors/touch/pat", "middle_back")
    adult.advance(1.0)
    adult_said = adult.said  # what it did stays readable after it is replaced

    child = TreeHarness.from_file(TOUCH_THANKS, TREES / "profiles" / "child.yaml")
    child.advance(1.0)  # nobody touches the child's robot

    assert len(adult_said) == 1
    assert adult.said == adult_said
    assert child.said == []
