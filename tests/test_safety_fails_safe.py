"""The safety envelope fails safe: a sensor it cannot trust counts as the worst case.

Every distance rule reads the chest's three range sensors (range_left, range_center,
range_right on the simulated vest) and the force rule the side pads (the ``force`` chip).
When one of them is unplugged, its reading gone stale or implausible, the envelope does
not read "nobody near": it holds the arms still (or, with ``when_unsure: slow``, moves them
slowly), stops a move under way, and says which rule and which device in the timeline, the
recording and the live view. Trees, remote commands and buttons all meet it.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import FORCE_LEFT_N, FORCE_RIGHT_N, default_catalogue
from engine.cli import main
from engine.clock import VirtualClock
from engine.hardware.config_file import load_robot_config
from engine.hardware.safety_envelope import EnvelopeWatcher, SafetyEnvelope, with_envelope
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording
from engine.recording.told import told_events
from engine.services.simulated import simulated_services
from engine.session.events import SafetyAction

ROOT = Path(__file__).resolve().parents[1]
SIM = ROOT / "examples" / "robots" / "sim.yaml"
RANGE_SENSORS = ("range_left", "range_center", "range_right")
ARM_UP = """\
name: arm_up
rate_hz: 20
root:
  Sequence:
    - OnEvent: {key: /sensors/gesture/last}
    - MoveServo: {joint: left_arm, angle_deg: 60}
"""


def run(tmp_path: Path, capsys, *events: str, extra: tuple[str, ...] = ()) -> list[dict]:
    """Run the arm_up tree (and whatever ``extra`` adds) on a 6 s scenario; the --json
    lines."""
    tree = tmp_path / "arm_up.yaml"
    tree.write_text(ARM_UP)
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 6\nevents:\n" + "".join(f"  - {e}\n" for e in events))
    args = ["run", "--fast", "--speech", "text", "--json", "--scenario", str(scenario)]
    assert main([*args, *extra, "--trees", str(tree), *_more_trees(extra)]) == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


def _more_trees(extra: tuple[str, ...]) -> list[str]:
    return [str(ROOT / "trees" / "iot_command.yaml")]


def unplugged(*devices: str, at: float = 1.0, seconds: float = 4.0) -> list[str]:
    return [f"{{at: {at}, unplug: {{device: {d}, seconds: {seconds}}}}}" for d in devices]


def refusals(lines: list[dict]) -> list[dict]:
    return [line for line in lines if line["event"] == "safety" and line["action"] == "refused"]


def test_with_every_chest_range_sensor_unplugged_a_tree_never_lifts_an_arm(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    lines = run(tmp_path, capsys, *unplugged(*RANGE_SENSORS), "{at: 2.0, gesture: wave}")
    [refused] = refusals(lines)
    assert refused["joint"] == "left_arm" and refused["rule"] == "still_within_mm"
    assert set(refused["devices"]) == set(RANGE_SENSORS)
    assert "range_center is offline" in refused["why"]
    assert "be trusted (" in refused["why"]
    failed = [line for line in lines if line["event"] == "outcome"]
    assert [(f["tree"], f["outcome"]) for f in failed] == [("arm_up", "failed")]
    moved = [line for line in lines if line["event"] == "action" and line["action"] == "servo"]
    assert all(m["args"]["joint"] != "left_arm" or m["args"].get("rest") for m in moved[1:])


@pytest.mark.parametrize(
    ("fault", "device", "rule"),
    [
        ("unplug: {device: range_left, seconds: 4}", "range_left", "still_within_mm"),
        ("unplug: {device: range_center, seconds: 4}", "range_center", "still_within_mm"),
        ("unplug: {device: range_right, seconds: 4}", "range_right", "still_within_mm"),
        ("unplug: {device: force, seconds: 4}", "force", "stop_above_n"),
        (
            "fault: {device: range_center, kind: nack, seconds: 4}",
            "range_center",
            "still_within_mm",
        ),
        ("fault: {device: force, kind: garbage, seconds: 4}", "force", "stop_above_n"),
    ],
)
def test_any_one_guarding_sensor_failing_is_enough_to_hold_the_arms(
    tmp_path, capsys, monkeypatch, fault, device, rule
):
    monkeypatch.chdir(ROOT)
    lines = run(tmp_path, capsys, f"{{at: 1.0, {fault}}}", "{at: 2.0, gesture: wave}")
    [refused] = refusals(lines)
    assert (refused["rule"], refused["devices"]) == (rule, [device])
    assert "be trusted (" in refused["why"]


def test_an_operator_s_arm_move_is_refused_while_the_force_pads_are_unplugged(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    lines = run(
        tmp_path,
        capsys,
        *unplugged("force"),
        "{at: 2.0, cloud: {type: move, args: {joint: right_arm, angle_deg: 30}}}",
    )
    [refused] = refusals(lines)
    assert refused["rule"] == "stop_above_n" and refused["devices"] == ["force"]
    report = next(
        line for line in lines if line["event"] == "action" and line["action"] == "report"
    )
    assert report["args"]["status"] == "failed"
    assert "force is offline" in str(report["args"]["result"])


def test_a_therapist_s_button_cannot_move_an_arm_past_an_unplugged_sensor(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    buttons = tmp_path / "buttons.yaml"
    buttons.write_text(
        "buttons:\n  - label: Wave\n    key: v\n    move: {joint: left_arm, angle_deg: 45}\n"
    )
    lines = run(
        tmp_path,
        capsys,
        *unplugged("range_center"),
        "{at: 2.0, press: Wave}",
        extra=("--buttons", str(buttons)),
    )
    [refused] = refusals(lines)
    assert refused["devices"] == ["range_center"]
    [press] = [line for line in lines if line["event"] == "press"]
    assert press["label"] == "Wave"
    assert any(
        line["event"] == "outcome" and line["tree"] == "buttons" and line["outcome"] == "failed"
        for line in lines
    )


def test_a_move_under_way_is_stopped_when_a_range_sensor_is_unplugged(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    slow_arm = ARM_UP.replace("angle_deg: 60}", "angle_deg: 60, speed_dps: 20}")
    tree = tmp_path / "arm_up.yaml"
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(
        "duration_s: 5\nevents:\n  - {at: 1.0, gesture: wave}\n"
        "  - {at: 1.5, unplug: {device: range_left, seconds: 3}}\n"
    )
    tree.write_text(slow_arm)
    args = ["run", "--fast", "--speech", "text", "--scenario", str(scenario), "--trees", str(tree)]
    assert main(args) == 0
    out = capsys.readouterr().out
    stop = next(line for line in out.splitlines() if " safety " in line)
    assert "stops left_arm where it is" in stop and "range_left" in stop
    assert 1.5 < float(stop.split()[0]) <= 2.2  # within a few polls of the unplug


@pytest.fixture
def envelope() -> tuple[SafetyEnvelope, Blackboard, VirtualClock]:
    """The simulated vest's envelope on a blackboard whose every guarding sensor is
    working and reads "nobody near, nobody pressing"."""
    clock = VirtualClock()
    blackboard = Blackboard(default_catalogue(), clock)
    blackboard.reset()
    envelope = SafetyEnvelope.of(load_robot_config(SIM), blackboard)
    for device in (*RANGE_SENSORS, "force"):
        blackboard.set(f"/devices/{device}/ok", True)
    fresh(blackboard)
    return envelope, blackboard, clock


def fresh(blackboard: Blackboard, **forces: float) -> None:
    """Every guarding sensor reads now: nothing in range, ``forces`` on the pads (N)."""
    for side in ("left", "center", "right"):
        blackboard.set(f"/sensors/range/{side}_mm", None)
    blackboard.set(FORCE_LEFT_N, forces.get("left", 0.0))
    blackboard.set(FORCE_RIGHT_N, forces.get("right", 0.0))


def test_readings_that_stopped_coming_count_as_the_worst_case(envelope):
    rules, blackboard, clock = envelope
    assert rules.hold_still() is None
    clock.advance(0.2)  # the pads poll at 20 Hz: four polls late is still fresh
    assert rules.hold_still() is None
    clock.advance(0.05)  # five: stale
    verdict = rules.hold_still()
    assert verdict is not None and verdict.rule == "stop_above_n"
    assert "force's last reading is 0.25 s old (stale)" in verdict.why
    fresh(blackboard)
    assert rules.hold_still() is None


@pytest.mark.parametrize("reading", [-40.0, 5000.0, math.nan, "garbage", True])
def test_an_implausible_force_counts_as_a_hard_press(envelope, reading):
    rules, blackboard, _ = envelope
    blackboard.set(FORCE_LEFT_N, reading)
    verdict = rules.refusal("left_arm", 30.0)
    assert verdict is not None and verdict.devices == ("force",)
    assert "not a plausible N reading" in verdict.why


def test_a_range_sensor_that_never_reported_counts_as_someone_at_the_chest(envelope):
    rules, blackboard, _ = envelope
    blackboard.set("/devices/range_left/ok", None)
    verdict = rules.hold_still()
    assert verdict is not None and verdict.devices == ("range_left",)
    assert "range_left has not reported yet" in verdict.why


def test_the_neck_is_not_held_by_the_arms_rules(envelope):
    rules, blackboard, _ = envelope
    blackboard.set("/devices/force/ok", False)
    assert rules.refusal("neck", 10.0) is None
    assert rules.refusal("left_arm", 10.0) is not None


def test_a_robot_that_may_move_slowly_when_unsure_moves_at_its_slow_speed(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    config = tmp_path / "slow.yaml"
    config.write_text(SIM.read_text().replace("when_unsure: refuse", "when_unsure: slow"))
    lines = run(
        tmp_path,
        capsys,
        *unplugged("range_center"),
        "{at: 2.0, gesture: wave}",
        extra=("--hardware", str(config)),
    )
    assert not refusals(lines)
    [slowed] = [line for line in lines if line["event"] == "safety"]
    assert slowed["action"] == "slowed" and slowed["devices"] == ["range_center"]
    [move] = [line for line in lines if line["event"] == "action" and line["action"] == "servo"]
    assert move["args"]["joint"] == "left_arm"


def test_validate_names_a_distance_rule_on_a_robot_without_range_sensors(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    text = SIM.read_text()
    for name in RANGE_SENSORS:
        text = "\n".join(line for line in text.splitlines() if not line.startswith(f"  {name}:"))
    config = tmp_path / "no_ranges.yaml"
    config.write_text(text + "\n")
    assert main(["validate", str(config)]) == 1
    err = capsys.readouterr()
    said = err.out + err.err
    assert "safety rule still_within_mm reads a range sensor (vl53l0x)" in said
    assert "every arm move would be refused" in said
    assert "no_ranges.yaml:" in said


def test_the_recording_keeps_which_rule_and_which_device_refused(
    tmp_path, capsys, monkeypatch, the_site_key: SiteKey
):
    monkeypatch.chdir(ROOT)
    tree = tmp_path / "arm_up.yaml"
    tree.write_text(ARM_UP)
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(
        "duration_s: 4\nevents:\n"
        + "".join(f"  - {e}\n" for e in [*unplugged(*RANGE_SENSORS), "{at: 2.0, gesture: wave}"])
    )
    record = tmp_path / "s.db"
    args = ["run", "--fast", "--speech", "text", "--scenario", str(scenario)]
    assert main([*args, "--trees", str(tree), "--record", str(record)]) == 0
    capsys.readouterr()
    [refused] = [
        e for e in told_events(Recording.open(record, the_site_key)) if isinstance(e, SafetyAction)
    ]
    assert refused.action == "refused" and refused.rule == "still_within_mm"
    assert set(refused.devices) == set(RANGE_SENSORS)


def test_a_sensor_that_cannot_be_trusted_never_hides_what_a_trusted_one_sees(envelope):
    rules, blackboard, _ = envelope
    rules.config = dataclasses.replace(rules.config, when_unsure="slow")  # doubts only slow
    blackboard.set("/devices/range_left/ok", False)
    blackboard.set("/sensors/range/center_mm", 50.0)
    verdict = rules.refusal("left_arm", 30.0)
    assert verdict is not None and verdict.devices == ("range_center",)
    assert "something is 50 mm from the chest" in verdict.why


def test_an_arm_held_away_from_rest_goes_back_once_the_envelope_allows(envelope):
    rules, blackboard, clock = envelope
    services = with_envelope(simulated_services(clock), rules)
    watcher = EnvelopeWatcher(services.servos, rules)  # type: ignore[arg-type]
    blackboard.set("/devices/range_center/ok", False)
    home, speed = services.servos.rest_pose("left_arm")
    rest = services.servos.move("left_arm", home, speed_dps=speed)
    assert not rest.done()  # not refused: held until it may
    inner = services.servos.inner  # type: ignore[attr-defined]
    watcher(clock.now())
    assert inner.calls == []  # still not allowed: the arm stays where it is
    blackboard.set("/devices/range_center/ok", True)
    fresh(blackboard)
    watcher(clock.now())
    assert inner.calls == [("left_arm", home, speed)]


def test_a_newer_move_of_the_arm_drops_the_rest_it_was_held_for(envelope):
    rules, blackboard, clock = envelope
    services = with_envelope(simulated_services(clock), rules)
    blackboard.set("/devices/force/ok", False)
    home, speed = services.servos.rest_pose("right_arm")
    rest = services.servos.move("right_arm", home, speed_dps=speed)
    services.servos.move("right_arm", 20.0)  # refused too, but the rest is moot now
    assert rest.done() and rest.error() is not None
