"""Safe halts: a behavior halted in the middle (reloaded, interrupted, the robot stopping)
leaves its joints at rest and its LEDs off."""

from __future__ import annotations

from pathlib import Path

from engine.blackboard.board import Blackboard
from engine.clock import VirtualClock
from engine.runtime.robot import Robot, load_behaviors
from engine.services.simulated import SimulatedLeds, SimulatedServos, simulated_services

WAVE = """\
name: wave_arm
rate_hz: 20
root:
  Sequence:
    - OnEvent: {key: /sensors/gesture/last}
    - SetLed: {color: yellow}
    - MoveServo: {joint: left_arm, angle_deg: 80, speed_dps: 60}
    - Wait: {seconds: 2}
    - MoveServo: {joint: left_arm, angle_deg: 0, speed_dps: 60}
    - SetLed: {color: "off"}
"""


def robot_waving(tmp_path: Path) -> tuple[Robot, VirtualClock, Path]:
    tree = tmp_path / "wave_arm.yaml"
    tree.write_text(WAVE)
    clock = VirtualClock()
    behaviors = load_behaviors([tree])
    services = simulated_services(clock, realistic=True)
    blackboard = Blackboard(behaviors.loader.catalogue, clock)
    blackboard.reset()
    robot = Robot(behaviors, clock=clock, services=services, blackboard=blackboard)
    blackboard.set("/sensors/gesture/last", "wave")
    tick_for(robot, clock, 2.0)  # the arm is up (80 deg at 60 deg/s: 1.33 s), waiting
    return robot, clock, tree


def tick_for(robot: Robot, clock: VirtualClock, seconds: float) -> None:
    """Tick the trees as the scheduler does, without stopping them at the end."""
    end = clock.now() + seconds
    while clock.now() < end - 1e-9:
        robot.scheduler.step()
        clock.advance(0.05)


def test_hot_reload_in_the_middle_of_a_wave_puts_the_arm_down_and_the_lights_out(tmp_path):
    robot, _, tree = robot_waving(tmp_path)
    servos = robot.services.servos
    assert isinstance(servos, SimulatedServos)
    assert servos.angles_deg["left_arm"] == 80  # up, waiting
    tree.write_text(WAVE.replace("seconds: 2", "seconds: 3"))  # the therapist edits it
    running = robot.scheduler.tree("wave_arm")
    running.replace(robot.behaviors.loader.load(tree))
    assert servos.calls[-1] == ("left_arm", 0.0, 40.0)  # home, at a third of 120 deg/s
    leds = robot.services.leds
    assert isinstance(leds, SimulatedLeds)
    assert leds.color == "off"


def test_stopping_the_robot_mid_wave_puts_the_arm_down(tmp_path):
    robot, _, _ = robot_waving(tmp_path)
    robot.scheduler.stop()
    robot.scheduler.run()  # ends at once, halting what runs
    servos = robot.services.servos
    assert isinstance(servos, SimulatedServos)
    assert servos.angles_deg["left_arm"] == 0.0
    rests = [r for r in robot.action_log.records if r.args.get("rest")]
    assert [(r.action, r.args.get("joint"), r.args.get("color")) for r in rests] == [
        ("servo", "left_arm", None),
        ("led", None, "off"),
    ]


def test_a_behavior_that_finished_is_not_moved_when_the_robot_stops(tmp_path):
    robot, clock, _ = robot_waving(tmp_path)
    tick_for(robot, clock, 4.0)  # the wave ended: arm down, LEDs off, by the tree
    count = len(robot.action_log.records)
    robot.scheduler.stop()
    robot.scheduler.run()
    assert len(robot.action_log.records) == count
