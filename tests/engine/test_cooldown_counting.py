"""Cooldown counts its rest from the end of the action, or from its start when asked.

The therapist's story: "lift the arm and say 'that tickles!'" takes 1.5 s; with a 5 s
rest counted from the start, a second pat 5 s after the first one is answered.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from engine.testing import TreeHarness

TREE = """\
name: tickles
rate_hz: 20
root:
  Sequence:
    - OnEvent: {{key: /sensors/gesture/last}}
    - Cooldown:
        seconds: 5
        counting_from: {counting_from}
        child:
          Sequence:
            - MoveServo: {{joint: left_arm, angle_deg: 45, speed_dps: 60}}
            - Say: {{text: "That tickles!"}}
            - MoveServo: {{joint: left_arm, angle_deg: 0, speed_dps: 60}}
"""


def tickles(tmp_path: Path, make: Callable[..., TreeHarness], counting_from: str) -> TreeHarness:
    path = tmp_path / "tickles.yaml"
    path.write_text(TREE.format(counting_from=counting_from))
    robot = make(path)
    robot.services.servos.default_speed_dps = 60.0  # type: ignore[attr-defined]
    return robot


def two_pats_five_seconds_apart(robot: TreeHarness) -> None:
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(5.0)
    robot.set("/sensors/gesture/last", "wave")
    robot.advance(2.0)


def test_counted_from_the_start_a_pat_five_seconds_later_is_answered(
    tmp_path: Path, tree_harness: Callable[..., TreeHarness]
) -> None:
    robot = tickles(tmp_path, tree_harness, "start")
    two_pats_five_seconds_apart(robot)
    assert robot.said == ["That tickles!", "That tickles!"]


def test_counted_from_the_end_the_rest_begins_after_the_arm_is_down(
    tmp_path: Path, tree_harness: Callable[..., TreeHarness]
) -> None:
    robot = tickles(tmp_path, tree_harness, "end")
    two_pats_five_seconds_apart(robot)  # the arm was down at 1.5 s: resting until 6.5 s
    assert robot.said == ["That tickles!"]
