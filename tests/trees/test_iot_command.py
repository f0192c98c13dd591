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
        ("say", {}, "say needs 'text'"),
        ("led", {"color": "plaid"}, "unknown color 'plaid'"),
        ("read", {"sensor": "smell"}, "unknown sensor 'smell'"),
        # checked by the same declarations as a tree's Say, SetLed and MoveServo
        ("say", {"text": "hi", "volume": 50}, "'volume' must be at most 1, got 50"),
        ("say", {"text": "hi", "volume": -3}, "'volume' must be at least 0, got -3"),
        ("say", {"text": "hi", "volume": float("nan")}, "'volume' must be a finite number"),
        ("say", {"text": "x" * 5000}, "'text' is 5000 characters long, more than 1000"),
        ("say", {"text": "hi", "loud": True}, "unknown argument 'loud' for say"),
        ("led", {"color": "pink", "seconds": 1e300}, "'seconds' must be at most 86400"),
        ("led", {"color": "pink", "seconds": float("nan")}, "'seconds' must be a finite number"),
        ("led", {"color": "pink", "seconds": float("-inf")}, "'seconds' must be a finite number"),
        ("move", {"joint": "neck", "angle_deg": 10**330}, "'angle_deg' must be a number below"),
        ("move", {"joint": "neck", "angle_deg": True}, "'angle_deg' must be a number, got True"),
        ("move", {"joint": "neck"}, "move needs 'angle_deg'"),
        ("move", {"joint": ["neck"], "angle_deg": 5}, "'joint' must be text"),
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


def test_a_refused_command_reports_its_own_failure_never_the_previous_result(
    robot: TreeHarness,
) -> None:
    robot.world.temperature_c = 22.0
    send(robot, "read", "cmd-1", sensor="temperature")
    robot.advance(1.0)
    send(robot, "move", "cmd-2", joint="neck", angle_deg=10**330)
    robot.advance(1.0)
    first, second = robot.did("report")
    assert (first["id"], first["status"]) == ("cmd-1", "succeeded")
    assert (second["id"], second["status"]) == ("cmd-2", "failed")
    assert "angle_deg" in second["result"]["error"]


def test_a_command_that_takes_too_long_fails_and_the_next_one_is_still_carried_out(
    robot: TreeHarness,
) -> None:
    send(robot, "led", "cmd-1", color="pink", seconds=3600)  # an hour of light
    robot.advance(61.0)
    send(robot, "say", "cmd-2", text="still here")
    robot.advance(2.0)
    reports = [(r["id"], r["status"]) for r in robot.did("report")]
    assert reports == [("cmd-1", "failed"), ("cmd-2", "succeeded")]
    assert "timed out after 60 s" in robot.did("report")[0]["result"]["error"]
    assert robot.said == ["still here"]


def test_an_operators_braces_are_said_as_written(robot: TreeHarness) -> None:
    send(robot, "say", text="I {love} you")
    robot.advance(1.0)
    assert robot.said == ["I {love} you"]
