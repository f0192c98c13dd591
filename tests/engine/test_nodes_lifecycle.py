"""Leaf lifecycles: an update() without a status, and a turn cut short by a Timeout."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import ClassVar

from py_trees.common import Status

from engine.nodes import Leaf
from engine.nodes.registry import builtin_registry
from engine.testing import TreeHarness

LEFT = {"joint": "neck", "angle_deg": 30.0, "speed_dps": 10.0}


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


class Forgetful(Leaf):
    """A developer's node whose update() forgets to return a status."""

    params: ClassVar = ()

    def update(self) -> Status:
        self.feedback_message = "did my thing"  # and no return
        return None  # type: ignore[return-value]


def test_an_update_returning_no_status_fails_the_node_and_names_its_class(
    tmp_path: Path,
) -> None:
    registry = builtin_registry()
    registry.add(Forgetful)
    tree = write(
        tmp_path,
        "forgetful.yaml",
        """\
        root:
          Selector:
            - Forgetful: {}
            - Say: {text: "plan B"}
        """,
    )
    robot = TreeHarness.from_file(tree, registry=registry, keep_node_errors=True)
    # Forgetful: FAILURE (not None), so the Selector goes on: Say: SUCCESS -> SUCCESS
    assert robot.tick() == Status.SUCCESS
    forgetful = robot.tree.root.children[0]
    assert forgetful.status == Status.FAILURE
    [(path, error)] = robot.node_errors
    assert path == "Selector/Forgetful"
    assert str(error) == "Forgetful.update() returned None, not a Status"
    assert robot.said == ["plan B"]


def test_a_turn_cut_short_by_a_timeout_is_started_again_next_round(tmp_path: Path) -> None:
    tree = write(
        tmp_path,
        "look.yaml",
        """\
        rate_hz: 10
        root:
          Timeout:
            seconds: 0.2
            child:
              LookToward: {joint: neck, turn_deg: 30, speed_dps: 10}
        """,
    )
    robot = TreeHarness.from_file(tree)
    robot.set("/sensors/range/left_mm", 300.0)
    robot.set("/sensors/range/center_mm", 800.0)
    # a 30 deg turn at 10 deg/s takes 3 s: RUNNING, RUNNING, then the Timeout: FAILURE
    assert [robot.tick().name for _ in range(3)] == ["RUNNING", "RUNNING", "FAILURE"]
    look = robot.tree.root.children[0]
    assert look.angle_deg == 0.0  # it never got there: the neck stopped 0.2 s into the turn
    # the round failed half-way: as on the robot, the neck goes back to rest
    [turn, rest] = robot.did("servo")
    assert turn == LEFT and rest["rest"] and rest["angle_deg"] == 0.0

    # the next round: the neck is not left, so it turns again
    assert robot.tick() == Status.RUNNING
    assert robot.did("servo") == [LEFT, rest, LEFT]


class Clumsy(Leaf):
    """A developer's node that raises in initialise() on its first round, then works for
    a tick, and raises again when it is halted."""

    rounds = 0

    def initialise(self) -> None:
        Clumsy.rounds += 1
        if Clumsy.rounds == 1:
            raise RuntimeError("forgot to connect")

    def update(self) -> Status:
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID:
            raise OSError("could not let go")


def test_exceptions_in_initialise_and_terminate_fail_the_node_not_the_tree(
    tmp_path: Path,
) -> None:
    registry = builtin_registry()
    registry.add(Clumsy)
    tree = write(
        tmp_path,
        "clumsy.yaml",
        """\
        root:
          Timeout:
            seconds: 0.25
            child: {Clumsy: {}}
        """,
    )
    robot = TreeHarness.from_file(tree, registry=registry, keep_node_errors=True)
    # round 1: initialise raised -> Clumsy FAILURE -> Timeout FAILURE
    assert robot.tick() == Status.FAILURE
    # round 2: RUNNING until the Timeout halts it; its terminate raises, the tree goes on
    assert robot.tick() == Status.RUNNING
    assert robot.advance(0.3) == Status.FAILURE
    assert [(path, type(error).__name__) for path, error in robot.node_errors] == [
        ("Timeout/Clumsy", "RuntimeError"),
        ("Timeout/Clumsy", "OSError"),
    ]
