"""Putting the hardware together: start-up without a device, buses that are not there."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import RealClock, VirtualClock
from engine.errors import DeviceError
from engine.hardware.assembly import build_hardware
from engine.hardware.config import RobotConfig, load_robot_config
from engine.hardware.sim_vest import build_sim_vest
from engine.scenario.world import World

from .conftest import ROOT

NO_SUCH_BUS = """\
name: nowhere
buses:
  i2c: {kind: i2c, number: 250}
devices:
  temperature: {chip: mcp9808}
"""


def test_a_device_missing_at_start_up_is_offline_not_fatal_and_comes_back(
    sim_config: RobotConfig,
):
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    world = World()
    vest = build_sim_vest(sim_config, world, clock)
    chip = vest.chips["temperature"]
    vest.i2c["i2c"].detach(chip.address)  # the MCP9808 is not soldered on (yet)
    hardware = build_hardware(sim_config, clock, board, vest=vest)
    try:
        board.commit()
        assert "temperature" in hardware.startup_problems
        assert "No such device or address" in hardware.startup_problems["temperature"]
        assert board.get("/devices/temperature/ok") is False
        assert board.get("/devices/touch/ok") is True

        vest.i2c["i2c"].attach(chip)
        clock.advance(2.5)
        hardware.run_due_probes(clock.now())  # a scheduler hook, inline
        board.commit()
        assert board.get("/devices/temperature/ok") is True
        clock.advance(0.3)  # a first conversion
        job = hardware.sensors.read("temperature")
        assert job.done() and job.result()["/sensors/temperature/c"] == 22.0
    finally:
        hardware.close()
        vest.close()


def test_a_bus_that_is_not_there_says_which_and_what_to_do(tmp_path: Path):
    if Path("/dev/i2c-250").exists():  # pragma: no cover - a machine with 251 I2C buses
        pytest.skip("this machine has /dev/i2c-250")
    path = tmp_path / "robot.yaml"
    path.write_text(NO_SUCH_BUS)
    config = load_robot_config(path)

    with pytest.raises(DeviceError) as caught:
        build_hardware(config, RealClock(), None)

    assert str(caught.value) == (
        "cannot open I2C bus 'i2c' (/dev/i2c-250): no such device file; enable I2C "
        "(raspi-config, or the board's device tree) and check N"
    )


def test_a_real_clock_needs_threads():
    config = load_robot_config(ROOT / "examples" / "robots" / "hbs2.yaml")

    with pytest.raises(ValueError, match="on a real clock use threaded=True"):
        build_hardware(config, RealClock(), None, threaded=False)
