"""Data flows one way: bus -> driver -> poller or service -> blackboard -> tree -> service.
A tree asks for an on-request reading and waits; the sensor service stages it, as a poller
stages a polled one, and no tree writes anything but /vars/."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.nodes.base import Leaf
from engine.nodes.registry import default_registry
from engine.testing import TreeHarness

TREES = Path(__file__).resolve().parents[2] / "trees"


def harness(tmp_path: Path, root: str) -> TreeHarness:
    path = tmp_path / "tree.yaml"
    path.write_text("name: t\nrate_hz: 10\nroot:\n" + textwrap.indent(textwrap.dedent(root), "  "))
    return TreeHarness.from_file(path)


def test_read_sensor_waits_until_the_staged_reading_is_on_the_blackboard(tmp_path: Path) -> None:
    robot = harness(tmp_path, "ReadSensor: {sensor: temperature}\n")
    robot.world.temperature_c = 21.5
    # tick 1: the reading is taken and staged, not yet committed: RUNNING
    assert robot.tick() == Status.RUNNING
    assert robot.get("/sensors/temperature/c") is None
    # tick 2: the commit between ticks took it in: SUCCESS
    assert robot.tick() == Status.SUCCESS
    assert robot.get("/sensors/temperature/c") == 21.5


def test_a_dialog_answers_with_the_fresh_reading_and_every_tree_sees_it_next_tick() -> None:
    robot = TreeHarness.from_file(TREES / "dialog.yaml")
    robot.world.temperature_c = 22.2
    robot.set("/speech/heard", "what is the temperature")
    robot.tick()
    assert robot.said == ["The temperature is 72 degrees"]  # answered in the same tick
    assert robot.get("/sensors/temperature/f") is None  # the tree wrote nothing
    robot.tick()
    assert robot.get("/sensors/temperature/f") == pytest.approx(71.96)  # staged, committed


def test_no_built_in_node_declares_a_write_outside_the_trees_variables() -> None:
    for node_type in default_registry(plugins=False):
        outside = [key for key in node_type.fixed_writes if not key.startswith("/vars/")]
        assert outside == [], node_type.name


class Tattler(Leaf):
    """Writes a variable it never declared (a bug a developer can make)."""

    def update(self) -> Status:
        self.write("/vars/secret", 1)
        return Status.SUCCESS


class SensorFaker(Leaf):
    """Declares a write to a sensor key: refused, trees write only /vars/."""

    writes = ("/sensors/touch/any",)


def test_a_node_writing_a_key_it_did_not_declare_fails_and_writes_nothing(tmp_path: Path) -> None:
    registry = default_registry(plugins=False)
    registry.add(Tattler)
    path = tmp_path / "tree.yaml"
    path.write_text("name: t\nrate_hz: 10\nroot:\n  Tattler: {}\n")
    robot = TreeHarness.from_file(path, registry=registry, keep_node_errors=True)
    assert robot.tick() == Status.FAILURE
    [(path_of_node, error)] = robot.node_errors
    assert path_of_node.endswith("Tattler")
    assert isinstance(error, PermissionError)
    assert "does not declare it" in str(error)
    assert robot.get("/vars/secret") is None


def test_a_node_declaring_a_write_outside_the_variables_is_refused_at_registration() -> None:
    with pytest.raises(TypeError, match="trees write only /vars/ keys"):
        default_registry(plugins=False).add(SensorFaker)


def test_by_default_the_harness_fails_a_test_with_the_node_s_own_exception(
    tmp_path: Path,
) -> None:
    registry = default_registry(plugins=False)
    registry.add(Tattler)
    path = tmp_path / "tree.yaml"
    path.write_text("name: t\nrate_hz: 10\nroot:\n  Tattler: {}\n")
    robot = TreeHarness.from_file(path, registry=registry)
    with pytest.raises(PermissionError, match="does not declare it"):
        robot.tick()
