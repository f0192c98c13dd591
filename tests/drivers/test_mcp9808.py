"""The MCP9808 driver against the simulated chip: warm rooms, cold mornings, slow updates."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.mcp9808 import (
    MCP9808,
    AlertFlags,
    celsius_to_fahrenheit,
    celsius_to_limit_word,
    raw_to_celsius,
)
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus, SimI2CDevice
from engine.sim.mcp9808 import SimMCP9808

ADDRESS = 0x18


class WordChip(SimI2CDevice):
    """A chip with fixed 16-bit registers: a stand-in for something that is not an MCP9808."""

    def __init__(self, address: int, words: dict[int, int]) -> None:
        super().__init__(address)
        self.words = words
        self.pointer = 0

    def write(self, data: bytes) -> None:
        if data:
            self.pointer = data[0]

    def read(self, length: int) -> bytes:
        word = self.words.get(self.pointer, 0)
        return bytes([word >> 8, word & 0xFF])[:length]


@pytest.fixture
def chip(bus: SimI2CBus, clock: VirtualClock) -> SimMCP9808:
    return bus.attach(SimMCP9808(clock))  # type: ignore[return-value]


def test_a_warm_room_reads_22_25_c(chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock) -> None:
    sensor = MCP9808(bus)
    chip.temperature_c = 22.25
    clock.advance(0.25)
    assert sensor.read_temperature_c() == 22.25
    assert sensor.read_temperature_f() == pytest.approx(72.05)


def test_negative_temperature_reads_below_zero(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    sensor = MCP9808(bus)
    chip.temperature_c = -10.5
    clock.advance(0.25)
    assert sensor.read_temperature_c() == -10.5
    assert sensor.read_temperature_f() == pytest.approx(13.1)


def test_the_reading_is_zero_until_the_first_conversion(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    sensor = MCP9808(bus)
    assert sensor.read_temperature_c() == 0.0
    clock.advance(0.25)
    assert sensor.read_temperature_c() == 22.0


def test_the_reading_changes_only_once_per_conversion_time(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    sensor = MCP9808(bus)
    clock.advance(0.25)
    chip.temperature_c = 30.0
    clock.advance(0.2)
    assert sensor.read_temperature_c() == 22.0  # the conversion under way is not done
    clock.advance(0.05)
    assert sensor.read_temperature_c() == 30.0


def test_a_coarser_resolution_quantizes_and_converts_faster(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    sensor = MCP9808(bus, resolution_c=0.5)
    assert sensor.conversion_time_s == 0.030
    chip.temperature_c = 22.8
    clock.advance(0.030)
    assert sensor.read_temperature_c() == 22.5

    sensor.set_resolution(0.0625)
    assert sensor.resolution_c == 0.0625
    clock.advance(0.030)
    assert sensor.read_temperature_c() == 22.5  # a 250 ms conversion has just begun
    clock.advance(0.220)
    assert sensor.read_temperature_c() == 22.75  # 22.8 truncated to 1/16 degC


@pytest.mark.parametrize(
    ("resolution_c", "expected"), [(0.5, -10.5), (0.25, -10.5), (0.125, -10.375), (0.0625, -10.375)]
)
def test_negative_readings_round_toward_minus_infinity(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock, resolution_c: float, expected: float
) -> None:
    sensor = MCP9808(bus, resolution_c=resolution_c)
    chip.temperature_c = -10.33
    clock.advance(sensor.conversion_time_s)
    assert sensor.read_temperature_c() == pytest.approx(expected)


def test_alert_flags_follow_the_limits(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    sensor = MCP9808(bus)
    sensor.set_alert_limits(lower_c=10.0, upper_c=30.0, critical_c=40.0)
    for temperature, flags in [
        (22.0, AlertFlags(critical=False, upper=False, lower=False)),
        (35.0, AlertFlags(critical=False, upper=True, lower=False)),
        (40.0, AlertFlags(critical=True, upper=True, lower=False)),
        (-5.0, AlertFlags(critical=False, upper=False, lower=True)),
    ]:
        chip.temperature_c = temperature
        clock.advance(0.25)
        assert sensor.read_alert_flags() == flags
        assert sensor.read_temperature_c() == temperature  # flags never leak into the value


def test_locked_window_ignores_new_limits(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    sensor = MCP9808(bus)
    sensor.set_alert_limits(lower_c=10.0, upper_c=30.0, critical_c=40.0)
    bus.write_i2c_block_data(ADDRESS, 0x01, [0x00, 0x40])  # window lock
    sensor.set_alert_limits(lower_c=0.0, upper_c=20.0, critical_c=40.0)
    chip.temperature_c = 25.0
    clock.advance(0.25)
    assert not sensor.read_alert_flags().upper


def test_a_chip_left_in_shutdown_is_woken(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    bus.write_i2c_block_data(ADDRESS, 0x01, [0x01, 0x00])  # SHDN
    clock.advance(1.0)
    assert bus.read_i2c_block_data(ADDRESS, 0x05, 2) == [0, 0]  # no conversion in shutdown

    sensor = MCP9808(bus)
    clock.advance(0.25)
    assert sensor.read_temperature_c() == 22.0


def test_ambient_register_is_big_endian_on_the_wire(
    chip: SimMCP9808, bus: SimI2CBus, clock: VirtualClock
) -> None:
    MCP9808(bus)
    bus.write_i2c_block_data(ADDRESS, 0x04, [0x02, 0x80])  # TCRIT 40 degC, so no flag
    bus.write_i2c_block_data(ADDRESS, 0x02, [0x02, 0x80])  # TUPPER 40 degC
    chip.temperature_c = 22.25
    clock.advance(0.25)
    assert bus.read_i2c_block_data(ADDRESS, 0x05, 2) == [0x01, 0x64]


def test_wrong_manufacturer_id_raises_device_error_naming_chip_and_address(
    bus: SimI2CBus,
) -> None:
    bus.attach(WordChip(ADDRESS, {0x06: 0x1234, 0x07: 0x0400}))
    with pytest.raises(DeviceError, match=r"MCP9808 at I2C 0x18.*manufacturer ID 0x1234"):
        MCP9808(bus)


def test_wrong_device_id_raises_device_error(bus: SimI2CBus) -> None:
    bus.attach(WordChip(ADDRESS, {0x06: 0x0054, 0x07: 0x0201}))
    with pytest.raises(DeviceError, match=r"device ID 0x02"):
        MCP9808(bus)


def test_missing_chip_raises_device_error(bus: SimI2CBus) -> None:
    with pytest.raises(DeviceError, match=r"MCP9808 not found at I2C 0x19"):
        MCP9808(bus, address=0x19)


def test_unknown_resolution_is_a_value_error(chip: SimMCP9808, bus: SimI2CBus) -> None:
    with pytest.raises(ValueError, match=r"resolution 0\.1"):
        MCP9808(bus, resolution_c=0.1)


def test_pure_conversions() -> None:
    assert raw_to_celsius(0x0164) == 22.25
    assert raw_to_celsius(0x1F58) == -10.5
    assert raw_to_celsius(0xE164) == 22.25  # flag bits ignored
    assert raw_to_celsius(0x1FFF) == -0.0625
    assert celsius_to_fahrenheit(-40.0) == -40.0
    assert celsius_to_fahrenheit(100.0) == 212.0
    assert celsius_to_limit_word(-10.5) == 0x1F58
    assert celsius_to_limit_word(40.1) == 0x0280
    with pytest.raises(ValueError, match="limit"):
        celsius_to_limit_word(300.0)


def test_garbage_never_becomes_a_temperature_outside_the_chips_range(
    chip: SimMCP9808, bus: SimI2CBus, read_garbage: Callable[..., Any]
) -> None:
    # "The temperature is -102 degrees" must never be said: the chip works at -40..125 C.
    sensor = MCP9808(bus)
    readings = read_garbage(bus, ADDRESS, sensor.read_temperature_c)
    assert readings.refused
    assert all(-40.0 <= celsius <= 125.0 for celsius in readings.believed)
    refusal = readings.refused[0]
    assert isinstance(refusal, DeviceError) and isinstance(refusal, ValueError)
    assert "MCP9808 at I2C 0x18: temperature" in str(refusal)
    assert "-40..125 degC" in str(refusal)
