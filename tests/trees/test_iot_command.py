"""iot_command: a remote command -> carried out -> its result reported (sections 3, 4.3)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from engine.testing import TreeHarness

TREE = Path(__file__).resolve().parents[2] / "trees" / "iot_command.yaml"


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def send(robot: TreeHarness, kind: str, command_id: str = "cmd-1", **args: Any) -> None:
    """The operator's command arrives in the robot's inbox."""
    robot.set("/iot/inbox", {"id": command_id, "type": kind, "args": args})


def test_a_say_command_is_spoken_and_reported_succeeded(robot: TreeHarness) -> None:
    send(robot, "say", text="hello from the cloud")
    robot.advance(1.0)
    assert robot.said == ["hello from the cloud"]
    assert robot.did("report") == [{"id": "cmd-1", "status": "succeeded", "result": None}]


def test_a_led_command_lights_the_face(robot: TreeHarness) -> None:
    send(robot, "led", color="blue", seconds=0.5)
    robot.advance(1.0)
    assert robot.did("led") == [{"color": "blue", "seconds": 0.5}]
    assert robot.did("report") == [{"id": "cmd-1", "status": "succeeded", "result": None}]


def test_a_move_command_moves_the_joint(robot: TreeHarness) -> None:
    send(robot, "move", joint="neck", angle_deg=20)
    robot.advance(1.0)
    assert robot.did("servo") == [{"joint": "neck", "angle_deg": 20.0}]
    assert robot.did("report") == [{"id": "cmd-1", "status": "succeeded", "result": None}]


def test_a_read_command_reports_the_temperature(robot: TreeHarness) -> None:
    robot.world.temperature_c = 22.2
    send(robot, "read", sensor="temperature")
    robot.advance(1.0)
    [report] = robot.did("report")
    assert report["status"] == "succeeded"
    assert report["result"] == {
        "/sensors/temperature/c": 22.2,
        "/sensors/temperature/f": pytest.approx(71.96),
    }


def test_a_read_command_reports_the_side_forces(robot: TreeHarness) -> None:
    robot.set("/sensors/force/left_n", 1.5)
    robot.set("/sensors/force/right_n", 0.5)
    send(robot, "read", sensor="force")
    robot.advance(1.0)
    assert robot.did("report") == [
        {
            "id": "cmd-1",
            "status": "succeeded",
            "result": {"/sensors/force/left_n": 1.5, "/sensors/force/right_n": 0.5},
        }
    ]


def test_a_command_is_carried_out_once_although_it_stays_on_the_blackboard(
    robot: TreeHarness,
) -> None:
    send(robot, "say", text="once")
    robot.advance(5.0)
    assert robot.said == ["once"]
    assert len(robot.did("report")) == 1


def test_an_unknown_command_type_is_reported_failed_with_the_reason(robot: TreeHarness) -> None:
    send(robot, "dance", style="tango")
    robot.advance(1.0)
    [report] = robot.did("report")
    assert (report["id"], report["status"]) == ("cmd-1", "failed")
    assert "unknown command type 'dance'" in report["result"]["error"]


@pytest.mark.parametrize(
    ("kind", "args", "reason"),
    [
        ("move", {"joint": "neck", "angle_deg": "far"}, "'angle_deg' must be a number, got 'far'"),
        ("say", {}, "'text' must be non-empty text"),
        ("led", {"color": "plaid"}, "unknown color 'plaid'"),
        ("read", {"sensor": "smell"}, "unknown sensor 'smell'"),
    ],
)
def test_bad_arguments_are_reported_failed_with_the_reason(
    robot: TreeHarness, kind: str, args: dict[str, Any], reason: str
) -> None:
    send(robot, kind, **args)
    robot.advance(1.0)
    [report] = robot.did("report")
    assert report["status"] == "failed"
    assert reason in report["result"]["error"]
    assert robot.did("say") == robot.did("led") == robot.did("servo") == []


def test_two_commands_arriving_in_the_same_tick_are_handled_one_per_tick(
    robot: TreeHarness,
) -> None:
    send(robot, "say", "cmd-1", text="first")
    send(robot, "say", "cmd-2", text="second")
    robot.tick()
    assert [report["id"] for report in robot.did("report")] == ["cmd-1"]
    robot.tick()
    assert [report["id"] for report in robot.did("report")] == ["cmd-1", "cmd-2"]
    assert robot.said == ["first", "second"]


def test_an_unplugged_speaker_is_reported_as_a_failed_command(robot: TreeHarness) -> None:
    robot.services.speech.fail_next = "speaker unplugged"
    send(robot, "say", text="hello")
    robot.advance(1.0)
    [report] = robot.did("report")
    assert report["status"] == "failed"
    assert "speaker unplugged" in report["result"]["error"]
