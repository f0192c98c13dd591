"""The MPR121 driver against the simulated chip: pads touched and released by a hand."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.mpr121 import MPR121
from engine.errors import DeviceError
from engine.sim.i2c_bus import RegisterFile, SimI2CBus, SimI2CDevice
from engine.sim.mpr121 import SimMPR121


class OtherChip(SimI2CDevice):
    """Something that is not an MPR121: plain byte registers that read back as written."""

    def __init__(self, address: int) -> None:
        super().__init__(address)
        self.registers = RegisterFile()

    def write(self, data: bytes) -> None:
        if data:
            self.registers.pointer = data[0]
            for value in data[1:]:
                self.registers.bytes[self.registers.pointer] = value
                self.registers.advance()

    def read(self, length: int) -> bytes:
        out = bytearray()
        for _ in range(length):
            out.append(self.registers.bytes[self.registers.pointer])
            self.registers.advance()
        return bytes(out)


@pytest.fixture
def bus() -> SimI2CBus:
    return SimI2CBus(VirtualClock())


@pytest.fixture
def chip(bus: SimI2CBus) -> SimMPR121:
    return bus.attach(SimMPR121())  # type: ignore[return-value]


def test_touching_pad_3_reports_it_until_the_hand_lifts(bus: SimI2CBus, chip: SimMPR121) -> None:
    pads = MPR121(bus)
    assert pads.touched() == [False] * 12

    chip.touch(3)
    assert pads.touched() == [pad == 3 for pad in range(12)]

    chip.touch(3, touching=False)
    assert pads.touched() == [False] * 12


def test_two_pads_touched_at_once_both_report(bus: SimI2CBus, chip: SimMPR121) -> None:
    pads = MPR121(bus)
    chip.touch(0)
    chip.touch(11)
    assert [pad for pad, touched in enumerate(pads.touched()) if touched] == [0, 11]


def test_start_up_leaves_the_chip_running_all_twelve_pads(bus: SimI2CBus, chip: SimMPR121) -> None:
    MPR121(bus, touch_threshold=20, release_threshold=10)
    assert chip.running
    assert bus.read_byte_data(0x5A, 0x5E) & 0x0F == 12
    assert all(chip.threshold(pad) == (20, 10) for pad in range(12))


def test_configuration_writes_are_ignored_while_the_chip_runs(
    bus: SimI2CBus, chip: SimMPR121
) -> None:
    MPR121(bus)
    bus.write_byte_data(0x5A, 0x41, 99)  # ELE0 touch threshold, written in run mode
    assert chip.threshold(0) == (12, 6)


def test_set_thresholds_stops_the_chip_writes_and_runs_it_again(
    bus: SimI2CBus, chip: SimMPR121
) -> None:
    pads = MPR121(bus)
    pads.set_thresholds(50, 25)

    assert all(chip.threshold(pad) == (50, 25) for pad in range(12))
    assert chip.running
    # a 40-count touch no longer clears the higher threshold
    chip.touch(3)
    assert pads.touched() == [False] * 12


def test_lower_threshold_makes_a_light_touch_count(bus: SimI2CBus) -> None:
    chip = SimMPR121(touch_delta_counts=8)
    bus.attach(chip)
    pads = MPR121(bus)
    chip.touch(5)
    assert not pads.touched()[5]

    pads.set_thresholds(4, 2)
    assert pads.touched()[5] is False  # baseline reloaded while touched: the touch is lost
    chip.touch(5, touching=False)
    chip.touch(5)
    assert pads.touched()[5]


def test_filtered_data_drops_under_a_finger_and_the_baseline_holds(
    bus: SimI2CBus, chip: SimMPR121
) -> None:
    pads = MPR121(bus)
    assert pads.filtered_data(3) == 600
    assert pads.baseline_data(3) == 600

    chip.touch(3)
    assert pads.filtered_data(3) == 560
    assert pads.baseline_data(3) == 600


def test_status_reports_no_pad_in_stop_mode(bus: SimI2CBus, chip: SimMPR121) -> None:
    MPR121(bus)
    chip.touch(3)
    bus.write_byte_data(0x5A, 0x5E, 0x00)  # stop mode
    assert bus.read_i2c_block_data(0x5A, 0x00, 2) == [0, 0]


def test_status_reports_only_enabled_electrodes(bus: SimI2CBus, chip: SimMPR121) -> None:
    pads = MPR121(bus)
    bus.write_byte_data(0x5A, 0x5E, 0x00)
    bus.write_byte_data(0x5A, 0x5E, 0x84)  # run ELE0..ELE3 only
    chip.touch(2)
    chip.touch(5)
    assert [pad for pad, touched in enumerate(pads.touched()) if touched] == [2]


def test_reading_the_status_clears_the_interrupt(bus: SimI2CBus, chip: SimMPR121) -> None:
    pads = MPR121(bus)
    chip.touch(7)
    assert chip.irq_asserted
    pads.touched()
    assert not chip.irq_asserted


def test_soft_reset_returns_registers_to_their_defaults(bus: SimI2CBus, chip: SimMPR121) -> None:
    MPR121(bus)
    bus.write_byte_data(0x5A, 0x80, 0x63)
    assert not chip.running
    assert bus.read_byte_data(0x5A, 0x5D) == 0x24
    assert bus.read_byte_data(0x5A, 0x5C) == 0x10


def test_wrong_identity_raises_device_error_naming_chip_and_address(bus: SimI2CBus) -> None:
    bus.attach(OtherChip(0x5A))
    with pytest.raises(DeviceError, match=r"MPR121 at I2C 0x5A.*CONFIG2"):
        MPR121(bus)


def test_missing_chip_raises_device_error_naming_chip_and_address(bus: SimI2CBus) -> None:
    with pytest.raises(DeviceError, match=r"MPR121 not found at I2C 0x5B"):
        MPR121(bus, address=0x5B)


@pytest.mark.parametrize(("touch", "release"), [(256, 6), (12, -1), (6, 12), (0, 0), (1.5, 1)])
def test_bad_thresholds_are_value_errors(bus: SimI2CBus, touch: int, release: int) -> None:
    bus.attach(SimMPR121())
    with pytest.raises(ValueError, match="threshold"):
        MPR121(bus, touch_threshold=touch, release_threshold=release)


def test_pad_outside_0_to_11_is_a_value_error(bus: SimI2CBus, chip: SimMPR121) -> None:
    pads = MPR121(bus)
    with pytest.raises(ValueError, match="pad 12"):
        pads.filtered_data(12)
    with pytest.raises(ValueError, match="pad 12"):
        chip.touch(12)


def test_garbage_never_becomes_phantom_touches(
    chip: SimMPR121, bus: SimI2CBus, read_garbage: Callable[..., Any]
) -> None:
    pads = MPR121(bus)
    readings = read_garbage(bus, 0x5A, pads.touched)
    # a status with proximity, reserved or over-current bits set is refused; only the
    # rare garbage that looks like a plain touch status can pass
    assert len(readings.refused) > 0.8 * 200
    assert "MPR121 at I2C 0x5A: touch status" in str(readings.refused[0])
