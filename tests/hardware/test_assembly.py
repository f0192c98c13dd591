"""Putting the hardware together: start-up without a device, buses that are not there, one
adapter shared with a mux, chips on XSHUT lines and behind a mux coming back."""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import RealClock, VirtualClock
from engine.drivers import mcp9808_registers, vl53l0x
from engine.errors import DeviceError
from engine.hardware.assembly import build_hardware
from engine.hardware.config import SIDES, BusConfig, RobotConfig
from engine.hardware.config_file import load_robot_config
from engine.hardware.robot_hardware import Hardware
from engine.hardware.sim_vest import SimVest, build_sim_vest
from engine.scenario.world import World
from engine.sim.i2c_bus import SimI2CBus

from .conftest import MUXED, ROOT, SimRobot

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


# -- a TCA9548A beside other chips: one adapter, one owner at a time -----------------------------
MUX_BESIDE_THERMOMETER = """\
name: shared
simulated: true
buses:
  i2c: {kind: i2c, number: 1}
devices:
  temperature: {chip: mcp9808}
  mux: {chip: tca9548a, address: 0x71}
  range_left: {chip: vl53l0x, side: left, mux: mux, channel: 0}
"""


class OneOpenFile:
    """``/dev/i2c-1`` as smbus2 drives it: the target address belongs to the open file.

    smbus2 sets it (``ioctl I2C_SLAVE``) when the next transfer is for another chip, then
    transfers (``ioctl I2C_SMBUS``) to whatever the file's address is by then: two system
    calls, and another thread using the same file may run between them. The chips at the
    end of the wires are the simulated ones.
    """

    def __init__(self, wires: SimI2CBus) -> None:
        self.wires = wires
        self.target: int | None = None

    def _to(self, address: int) -> int:
        if address != self.target:
            self.target = address
        os.sched_yield()  # a system call: other threads run meanwhile
        assert self.target is not None
        return self.target

    def read_byte(self, address: int, force: bool | None = None) -> int:
        return self.wires.read_byte(self._to(address))

    def write_byte(self, address: int, value: int, force: bool | None = None) -> None:
        self.wires.write_byte(self._to(address), value)

    def read_byte_data(self, address: int, register: int, force: bool | None = None) -> int:
        return self.wires.read_byte_data(self._to(address), register)

    def write_byte_data(
        self, address: int, register: int, value: int, force: bool | None = None
    ) -> None:
        self.wires.write_byte_data(self._to(address), register, value)

    def read_i2c_block_data(
        self, address: int, register: int, length: int, force: bool | None = None
    ) -> list[int]:
        return self.wires.read_i2c_block_data(self._to(address), register, length)

    def write_i2c_block_data(
        self, address: int, register: int, data: list[int], force: bool | None = None
    ) -> None:
        self.wires.write_i2c_block_data(self._to(address), register, data)


class VestOnOneFile:
    """The simulated vest, its I2C bus opened as one smbus2 file."""

    def __init__(self, vest: SimVest) -> None:
        self.vest = vest
        self.clock = vest.clock

    def open_i2c(self, bus: BusConfig) -> OneOpenFile:
        return OneOpenFile(self.vest.open_i2c(bus))

    def __getattr__(self, name: str) -> Any:
        return getattr(self.vest, name)


def test_upstream_chips_and_chips_behind_the_mux_never_get_each_other_s_transfers(tmp_path):
    path = tmp_path / "shared.yaml"
    path.write_text(MUX_BESIDE_THERMOMETER)
    config = load_robot_config(path)
    clock = VirtualClock()
    vest = build_sim_vest(config, World(), clock)
    hardware = build_hardware(config, clock, None, vest=VestOnOneFile(vest), threaded=True)
    wrong: list[object] = []

    def keep_asking(device: str, ask: Callable[[Any], object], expected: object) -> None:
        handle = hardware.handles[device]
        for _ in range(1000):
            try:
                answer = handle.call(ask, timeout_s=5.0)
            except OSError as error:
                answer = error
            if answer != expected:
                wrong.append((device, answer))

    thermometer = threading.Thread(
        target=keep_asking,
        args=(
            "temperature",
            lambda bus: bus.read_i2c_block_data(0x18, mcp9808_registers.MANUFACTURER_ID, 2),
            [0x00, 0x54],
        ),
    )
    ranger = threading.Thread(
        target=keep_asking,
        args=(
            "range_left",
            lambda bus: bus.read_byte_data(0x29, vl53l0x.IDENTIFICATION_MODEL_ID),
            0xEE,
        ),
    )
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # threads take turns as often as the interpreter allows
    try:
        assert hardware.startup_problems == {}
        thermometer.start()
        ranger.start()
        thermometer.join()
        ranger.join()
    finally:
        sys.setswitchinterval(interval)
        hardware.close()
        vest.close()

    assert wrong == []


# -- VL53L0X chips on XSHUT lines come back -------------------------------------------------------
def run_hooks(hardware: Hardware, board: Blackboard, clock: VirtualClock, seconds: float) -> None:
    """The scheduler's hooks every 0.1 s for ``seconds``, as ``vest run --fast`` calls them."""
    for _ in range(round(seconds / 0.1)):
        clock.advance(0.1)
        for hook in hardware.hooks:
            hook(clock.now())
        board.commit()


def test_a_range_sensor_that_lost_power_is_switched_on_again_and_moved_to_its_address(
    sim_robot: SimRobot,
):
    sim_robot.obstacle(left=300.0)
    sim_robot.run_for(1.0)
    assert sim_robot.key("/sensors/range/left_mm") == 300.0
    chip = sim_robot.vest.chips["range_left"]

    chip.set_xshut(False)  # its cable is pulled and pushed back: it boots at 0x29 again
    chip.set_xshut(True)
    sim_robot.obstacle(left=450.0)
    sim_robot.run_for(1.0)

    assert sim_robot.key("/sensors/range/left_mm") == 450.0
    assert sim_robot.key("/devices/range_left/ok") is True
    assert chip.address == 0x30
    assert 0x29 not in sim_robot.vest.i2c["i2c"].addresses
    assert sim_robot.hardware.chains["i2c"].reboots["range_left"] == 1


def test_range_sensors_that_missed_their_start_up_come_up_at_their_first_polls(
    sim_config: RobotConfig,
):
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    world = World(range_mm={"left": 300.0, "center": 800.0, "right": 900.0})
    vest = build_sim_vest(sim_config, world, clock)
    vest.i2c["i2c"].inject("nack", 0.005, 0x29)  # a glitch while the first two boot
    hardware = build_hardware(sim_config, clock, board, vest=vest)
    try:
        assert "range_left" in hardware.startup_problems
        assert not vest.chips["range_left"].powered  # left in standby, out of the way

        run_hooks(hardware, board, clock, 1.0)

        assert [board.get(f"/sensors/range/{side}_mm") for side in SIDES] == [300, 800, 900]
        assert all(board.get(f"/devices/range_{side}/ok") for side in SIDES)
    finally:
        hardware.close()
        vest.close()


def test_a_chip_brought_back_does_not_disturb_the_last_one_staying_at_0x29(tmp_path):
    text = (ROOT / "examples" / "robots" / "sim.yaml").read_text()
    path = tmp_path / "last_at_0x29.yaml"
    path.write_text(text.replace("address: 0x32, xshut: 22", "address: 0x29, xshut: 22"))
    config = load_robot_config(path)
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    world = World(range_mm={"left": 300.0, "center": 800.0, "right": 900.0})
    vest = build_sim_vest(config, world, clock)
    vest.i2c["i2c"].inject("nack", 0.003, 0x29)  # the first one misses its start-up
    hardware = build_hardware(config, clock, board, vest=vest)
    try:
        assert "range_left" in hardware.startup_problems
        assert "range_right" not in hardware.startup_problems

        run_hooks(hardware, board, clock, 1.0)
        world.range_mm.update(left=350.0, right=950.0)
        world.changed("range")
        run_hooks(hardware, board, clock, 1.0)

        assert [board.get(f"/sensors/range/{side}_mm") for side in SIDES] == [350, 800, 950]
        assert (vest.chips["range_left"].address, vest.chips["range_right"].address) == (
            0x30,
            0x29,
        )
        assert hardware.chains["i2c"].reboots == {
            "range_left": 1,
            "range_center": 0,
            "range_right": 0,
        }
    finally:
        hardware.close()
        vest.close()


# -- a mux late at start-up ---------------------------------------------------------------------


def test_sensors_behind_a_mux_that_was_late_at_start_up_read_once_it_answers(tmp_path):
    path = tmp_path / "muxed.yaml"
    path.write_text(MUXED)
    config = load_robot_config(path)
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    world = World(range_mm={"left": 250.0, "center": 600.0, "right": 900.0})
    vest = build_sim_vest(config, world, clock)
    vest.unplug("mux", 0.5)  # slow to power up
    hardware = build_hardware(config, clock, board, vest=vest)
    try:
        board.commit()
        assert set(hardware.startup_problems) == {"mux", *(f"range_{s}" for s in SIDES)}
        assert board.get("/devices/mux/ok") is False

        run_hooks(hardware, board, clock, 3.0)

        assert [board.get(f"/sensors/range/{side}_mm") for side in SIDES] == [250, 600, 900]
        assert board.get("/devices/mux/ok") is True
        assert all(board.get(f"/devices/range_{side}/ok") for side in SIDES)
    finally:
        hardware.close()
        vest.close()


def test_a_mux_that_stops_answering_is_shown_not_ok_and_back_when_it_answers(tmp_path):
    path = tmp_path / "muxed.yaml"
    path.write_text(MUXED)
    config = load_robot_config(path)
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    vest = build_sim_vest(config, World(range_mm={"left": 250.0}), clock)
    hardware = build_hardware(config, clock, board, vest=vest)
    try:
        run_hooks(hardware, board, clock, 0.5)
        assert board.get("/devices/mux/ok") is True

        vest.unplug("mux", 2.0)
        run_hooks(hardware, board, clock, 1.0)
        assert board.get("/devices/mux/ok") is False
        assert "TCA9548A at 0x71" in (hardware.health["mux"].last_error or "")

        run_hooks(hardware, board, clock, 4.0)
        assert board.get("/devices/mux/ok") is True
        assert board.get("/sensors/range/left_mm") == 250.0
    finally:
        hardware.close()
        vest.close()


# -- a device whose poller cannot be made ---------------------------------------------------------
def test_a_force_sensor_whose_poller_cannot_be_made_is_shown_not_ok(sim_config: RobotConfig):
    # The config checker refuses such a table; a config built in code can still carry one.
    force = sim_config.device("force")
    broken = dataclasses.replace(
        force.pads[0], calibration=((0.0, 0.0), (math.nan, 0.2), (3.0, 6.0))
    )
    config = dataclasses.replace(
        sim_config,
        devices={
            **sim_config.devices,
            "force": dataclasses.replace(force, pads=(broken, *force.pads[1:])),
        },
    )
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    vest = build_sim_vest(sim_config, World(), clock)
    hardware = build_hardware(config, clock, board, vest=vest)
    try:
        board.commit()
        assert "not finite" in hardware.startup_problems["force"]
        assert board.get("/devices/force/ok") is False
        assert "force" not in [poller.name for poller in hardware.pollers]
        assert board.get("/devices/touch/ok") is True
    finally:
        hardware.close()
        vest.close()


def test_a_maestro_missing_at_start_up_does_not_stop_the_robot_and_moves_fail_in_words(
    sim_config: RobotConfig, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    vest = build_sim_vest(sim_config, World(), clock)
    missing = str(tmp_path / "ttyACM0")  # the USB cable is not plugged in
    monkeypatch.setattr(vest, "serial_port", lambda bus: missing)
    hardware = build_hardware(sim_config, clock, board, vest=vest)
    try:
        board.commit()
        assert "no such file" in hardware.startup_problems["servos"]
        assert board.get("/devices/servos/ok") is False
        assert board.get("/devices/touch/ok") is True  # the rest of the vest works
        job = hardware.servos.move("neck", 10.0)
        assert job.done() and "no such file" in str(job.error())
    finally:
        hardware.close()
        vest.close()
