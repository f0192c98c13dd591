"""The robot on the simulated vest, without the CLI: world, chips, drivers, pollers, trees."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from engine.clock import VirtualClock
from engine.hardware.config import RobotConfig
from engine.hardware.config_file import load_robot_config
from engine.hardware.robot_hardware import Hardware
from engine.hardware.sim_vest import SimVest
from engine.runtime.robot import load_behaviors
from engine.runtime.robot_factory import build_robot
from engine.services.simulated import SimulatedIot, SimulatedSpeech

ROOT = Path(__file__).resolve().parents[2]
SIM_CONFIG = ROOT / "examples" / "robots" / "sim.yaml"


class SimRobot:
    """Every tree of trees/ on the simulated vest of examples/robots/sim.yaml.

    Speech is simulated (``said``); LEDs, servos and sensors go through the drivers to the
    simulated chips. Time is virtual: :meth:`run_for` ticks the scheduler, whose hooks poll.
    """

    def __init__(self, config: RobotConfig) -> None:
        self.clock = VirtualClock()
        self.speech = SimulatedSpeech(self.clock)
        self.iot = SimulatedIot()
        behaviors = load_behaviors([ROOT / "trees"], dialogs_dir=ROOT / "dialogs")
        self.assembled = build_robot(
            behaviors, config, clock=self.clock, speech=self.speech, iot=self.iot
        )
        self.robot = self.assembled.robot
        self.blackboard = self.assembled.blackboard
        self.world = self.assembled.world
        self.hardware: Hardware = self.assembled.hardware
        assert self.assembled.vest is not None
        self.vest: SimVest = self.assembled.vest
        self.services = self.robot.services

    @property
    def said(self) -> list[str]:
        return [text for text, _volume in self.speech.calls]

    def run_for(self, seconds: float) -> None:
        """Tick the robot for ``seconds`` of virtual time (what runs goes on after)."""
        self.robot.scheduler.run(until_s=self.clock.now() + seconds, halt_at_end=False)

    def key(self, key: str) -> object:
        return self.blackboard.get(key)

    # -- the world -------------------------------------------------------------------------
    def touch(self, pad: int, down: bool = True) -> None:
        self.world.touched[pad] = down
        self.world.changed("touch")

    def squeeze(self, left_n: float, right_n: float) -> None:
        self.world.force_n.update(left=left_n, right=right_n)
        self.world.changed("force")

    def obstacle(self, **sides_mm: float | None) -> None:
        self.world.range_mm.update(sides_mm)
        self.world.changed("range")

    def room_at(self, celsius: float) -> None:
        self.world.temperature_c = celsius
        self.world.changed("temperature")

    def object_ahead(self, cm: float | None) -> None:
        self.world.ultrasound_cm = cm
        self.world.changed("ultrasound")

    def hear(self, text: str) -> None:
        self.world.happened("hear", text)

    def close(self) -> None:
        self.assembled.close()


@pytest.fixture
def sim_config() -> RobotConfig:
    return load_robot_config(SIM_CONFIG)


@pytest.fixture
def sim_robot(sim_config: RobotConfig) -> Iterator[SimRobot]:
    robot = SimRobot(sim_config)
    try:
        yield robot
    finally:
        robot.close()


# three range sensors, all at 0x29, each on its own channel of a TCA9548A
MUXED = """\
name: muxed
simulated: true
buses:
  i2c: {kind: i2c, number: 1}
devices:
  mux: {chip: tca9548a, address: 0x71}
  range_left: {chip: vl53l0x, side: left, mux: mux, channel: 0}
  range_center: {chip: vl53l0x, side: center, mux: mux, channel: 3}
  range_right: {chip: vl53l0x, side: right, mux: mux, channel: 7}
"""
