"""The safety envelope: limits in the robot config that no tree, remote command or button
can lift, checked on every service call and by a watcher between ticks.

The simulated vest's config (examples/robots/sim.yaml) holds the arms still within 100 mm
of the chest, slows them to 30 deg/s within 300 mm, stops them above 12 N of side force,
speaks at most at volume 0.9 and lights the face at most at 0.8 brightness.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    RANGE_CENTER_MM,
    default_catalogue,
)
from engine.cli import main
from engine.clock import VirtualClock
from engine.hardware.config_file import load_robot_config
from engine.hardware.safety_envelope import SafetyEnvelope, SafetyRefusedError, with_envelope
from engine.services.simulated import simulated_services

ROOT = Path(__file__).resolve().parents[1]
SIM = ROOT / "examples" / "robots" / "sim.yaml"

ARM_UP = """\
name: arm_up
rate_hz: 20
root:
  Sequence:
    - OnEvent: {key: /sensors/gesture/last}
    - MoveServo: {joint: left_arm, angle_deg: 80, speed_dps: 40}
"""


def run(tmp_path: Path, capsys, trees: list[Path], *events: str, as_json: bool = False) -> str:
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 5\nevents:\n" + "".join(f"  - {e}\n" for e in events))
    args = ["run", "--fast", "--speech", "text", "--scenario", str(scenario)]
    args += ["--json"] if as_json else []
    assert main([*args, "--trees", *map(str, trees)]) == 0
    return capsys.readouterr().out


def arm_up(tmp_path: Path) -> Path:
    path = tmp_path / "arm_up.yaml"
    path.write_text(ARM_UP)
    return path


def test_a_tree_raising_an_arm_while_someone_leans_on_the_chest_fails_with_the_reason(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    out = run(
        tmp_path,
        capsys,
        [arm_up(tmp_path)],
        "{at: 1.0, obstacle: {center_mm: 80, seconds: 2.0}}",
        "{at: 1.5, gesture: wave}",
    )
    refused = next(line for line in out.splitlines() if "could not" in line)
    assert "arm_up" in refused
    assert "turns left_arm to 80 deg" in refused
    assert "safety: something is" in refused
    assert "mm from the chest, closer than 100 mm: the arms stay still" in refused


def test_a_remote_command_to_move_the_arm_is_refused_and_reported_failed_with_the_reason(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    lines = run(
        tmp_path,
        capsys,
        [ROOT / "trees" / "iot_command.yaml"],
        "{at: 1.0, obstacle: {center_mm: 80, seconds: 2.0}}",
        "{at: 1.5, cloud: {type: move, args: {joint: left_arm, angle_deg: 45}}}",
        as_json=True,
    )
    actions = [json.loads(line) for line in lines.splitlines()]
    report = next(a for a in actions if a["event"] == "action" and a["action"] == "report")
    assert report["args"]["status"] == "failed"
    assert "safety: something is" in str(report["args"]["result"])


def test_a_hard_squeeze_stops_an_arm_move_under_way_where_the_arm_is(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    out = run(
        tmp_path,
        capsys,
        [arm_up(tmp_path)],
        "{at: 1.0, gesture: wave}",  # 80 deg at 40 deg/s: two seconds of moving
        "{at: 1.5, squeeze: {left_n: 15.0, seconds: 1.0}}",
    )
    stop = next(line for line in out.splitlines() if " safety " in line)
    assert "stops left_arm where it is: a side force of" in stop
    assert "is above 12 N" in stop
    assert 1.5 <= float(stop.split()[0]) < 1.7  # within a poll and a tick of the squeeze


@pytest.fixture
def envelope() -> tuple[SafetyEnvelope, Blackboard]:
    """The simulated vest's envelope, its range sensors and force pads working and read
    just now: nobody near, nobody pressing."""
    clock = VirtualClock()
    blackboard = Blackboard(default_catalogue(), clock)
    blackboard.reset()
    for device in ("range_left", "range_center", "range_right", "force"):
        blackboard.set(f"/devices/{device}/ok", True)
    for side in ("left", "center", "right"):
        blackboard.set(f"/sensors/range/{side}_mm", None)
    blackboard.set(FORCE_LEFT_N, 0.0)
    blackboard.set(FORCE_RIGHT_N, 0.0)
    return SafetyEnvelope.of(load_robot_config(SIM), blackboard), blackboard


def test_an_arm_near_a_person_moves_slowly_and_one_farther_away_at_its_asked_speed(envelope):
    rules, blackboard = envelope
    blackboard.set(RANGE_CENTER_MM, 200.0)
    assert rules.speed_dps("left_arm", 60.0)[0] == 30.0
    assert rules.speed_dps("left_arm", None)[0] == 30.0  # the joint's limit would be faster
    assert rules.speed_dps("neck", 90.0) == (90.0, None)  # the neck is not an arm
    slowed = rules.speed_dps("left_arm", 60.0)[1]
    assert slowed is not None and slowed.rule == "slow_within_mm"
    assert slowed.devices == ("range_center",)
    blackboard.set(RANGE_CENTER_MM, 500.0)
    assert rules.speed_dps("left_arm", 60.0) == (60.0, None)


def test_speech_is_never_louder_and_the_face_never_brighter_than_the_config_allows(envelope):
    rules, _ = envelope
    clock = VirtualClock()
    services = with_envelope(simulated_services(clock), rules)
    services.speech.say("HELLO!", volume=1.0)
    services.speech.say("hello", volume=0.5)
    services.speech.say("default")
    services.leds.set_color("white")
    services.leds.set_color("#101010")  # already dim: unchanged
    inner_speech = services.speech.inner  # type: ignore[attr-defined]
    assert [volume for _, volume in inner_speech.calls] == [0.9, 0.5, 0.9]
    inner_leds = services.leds.inner  # type: ignore[attr-defined]
    assert [color for color, _ in inner_leds.calls] == ["#CCCCCC", "#101010"]


def test_a_hand_pressing_hard_on_the_side_holds_the_arms_still_but_not_the_neck(envelope):
    rules, blackboard = envelope
    services = with_envelope(simulated_services(VirtualClock()), rules)
    blackboard.set(FORCE_LEFT_N, 14.0)
    refused = services.servos.move("right_arm", 10.0)
    assert isinstance(refused.error(), SafetyRefusedError)
    assert "a side force of 14.0 N is above 12 N" in str(refused.error())
    assert services.servos.move("neck", 10.0).error() is None


def test_a_safety_section_naming_a_joint_the_robot_lacks_is_refused_with_its_place(
    tmp_path, capsys
):
    config = SIM.read_text().replace("arms: [left_arm, right_arm]", "arms: [left_arm, rigth_arm]")
    path = tmp_path / "robot.yaml"
    path.write_text(config)
    assert main(["validate", str(path)]) == 1
    err = capsys.readouterr().err
    assert "safety names joint 'rigth_arm', which the robot does not have" in err
    assert "did you mean 'right_arm'" in err
    line = next(n for n, text in enumerate(config.splitlines(), 1) if "rigth_arm" in text)
    assert f"{path}:{line}:" in err
