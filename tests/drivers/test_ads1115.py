"""The ADS1115 driver against the simulated chip, and the force pad's volts-to-newtons path."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.ads1115 import ADS1115, lowest_single_ended_code, raw_to_volts
from engine.drivers.force_calibration import ForceCalibration
from engine.errors import DeviceError
from engine.sim.ads1115 import SimADS1115
from engine.sim.fsr import fsr406_volts
from engine.sim.i2c_bus import SimI2CBus

ADDRESS = 0x48


@pytest.fixture
def chip(bus: SimI2CBus, clock: VirtualClock) -> SimADS1115:
    return bus.attach(SimADS1115(clock))  # type: ignore[return-value]


def start_conversion(bus: SimI2CBus, config: int) -> None:
    bus.write_i2c_block_data(ADDRESS, 0x01, [config >> 8, config & 0xFF])


def read_register(bus: SimI2CBus, register: int) -> int:
    msb, lsb = bus.read_i2c_block_data(ADDRESS, register, 2)
    return msb << 8 | lsb


# OS=1, AIN0 vs GND, +/-4.096 V, single shot, 128 SPS, comparator off
START_AIN0 = 0x8000 | 0b100 << 12 | 0b001 << 9 | 0x0100 | 0b100 << 5 | 0x0003


def test_each_channel_reads_its_own_volts(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    adc = ADS1115(bus, clock=clock)
    for channel, volts in enumerate([0.5, 1.25, 2.0, 3.3]):
        chip.set_input_volts(channel, volts)
    assert [round(adc.read_volts(channel), 3) for channel in range(4)] == [0.5, 1.25, 2.0, 3.3]


@pytest.mark.parametrize(("gain", "full_scale_v", "volts"), [(1, 4.096, 1.8), (16, 0.256, 0.2)])
def test_volts_read_at_two_gains(
    chip: SimADS1115,
    bus: SimI2CBus,
    clock: VirtualClock,
    gain: float,
    full_scale_v: float,
    volts: float,
) -> None:
    adc = ADS1115(bus, gain=gain, clock=clock)
    chip.set_input_volts(1, volts)
    assert adc.full_scale_v == full_scale_v
    assert adc.read_volts(1) == pytest.approx(volts, abs=full_scale_v / 32768)


def test_finer_gain_resolves_smaller_steps(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip.set_input_volts(0, 0.1)
    coarse = ADS1115(bus, gain=2 / 3, clock=clock).read_raw(0)
    fine = ADS1115(bus, gain=16, clock=clock).read_raw(0)
    assert coarse == round(0.1 / 6.144 * 32768)
    assert fine == round(0.1 / 0.256 * 32768)


def test_a_reading_waits_one_conversion_on_the_clock(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    adc = ADS1115(bus, data_rate_sps=8, clock=clock)
    before = clock.now()
    adc.read_volts(0)
    assert 1 / 8 <= clock.now() - before <= 1.2 / 8


def test_while_converting_the_previous_result_stays(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip.set_input_volts(0, 1.0)
    start_conversion(bus, START_AIN0)
    clock.advance(1 / 128)
    first = read_register(bus, 0x00)

    chip.set_input_volts(0, 2.0)
    start_conversion(bus, START_AIN0)
    clock.advance(0.5 / 128)
    assert read_register(bus, 0x01) & 0x8000 == 0  # OS reads 0: converting
    assert read_register(bus, 0x00) == first

    clock.advance(0.5 / 128)
    assert read_register(bus, 0x01) & 0x8000  # idle again
    assert read_register(bus, 0x00) == round(2.0 / 4.096 * 32768)


def test_config_reads_back_as_written_with_os_set_when_idle(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    assert read_register(bus, 0x01) == 0x8583  # power-on default
    start_conversion(bus, START_AIN0)
    assert read_register(bus, 0x01) == START_AIN0 & 0x7FFF
    clock.advance(1 / 128)
    assert read_register(bus, 0x01) == START_AIN0


def test_inputs_beyond_full_scale_clip(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    adc = ADS1115(bus, gain=4, clock=clock)  # +/-1.024 V
    chip.set_input_volts(2, 3.0)
    assert adc.read_raw(2) == 0x7FFF
    assert adc.read_volts(2) == pytest.approx(1.024, abs=1e-4)


def test_input_below_ground_reads_a_negative_code(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    adc = ADS1115(bus, gain=16, clock=clock)  # +/-0.256 V
    chip.set_input_volts(3, -0.1)
    assert adc.read_raw(3) == -12800
    assert adc.read_volts(3) == pytest.approx(-0.1, abs=1e-5)


def test_differential_input_below_minus_full_scale_clips_at_0x8000(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip.set_input_volts(0, 0.0)
    chip.set_input_volts(1, 3.0)
    # OS=1, AIN0 - AIN1, +/-2.048 V, single shot, 128 SPS
    start_conversion(bus, 0x8000 | 0b000 << 12 | 0b010 << 9 | 0x0100 | 0b100 << 5 | 0x0003)
    clock.advance(1 / 128)
    assert read_register(bus, 0x00) == 0x8000


def test_raw_to_volts_handles_negative_codes() -> None:
    assert raw_to_volts(-32768, 4.096) == -4.096
    assert raw_to_volts(16384, 2.048) == 1.024
    assert raw_to_volts(-1, 0.256) == pytest.approx(-0.256 / 32768)
    with pytest.raises(ValueError, match="32768"):
        raw_to_volts(32768, 4.096)


@pytest.mark.parametrize("gain", [3, 0.5, 32])
def test_unknown_gain_is_a_value_error(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock, gain: float
) -> None:
    with pytest.raises(ValueError, match="gain"):
        ADS1115(bus, gain=gain, clock=clock)


@pytest.mark.parametrize("rate", [0, 100, 1000])
def test_unknown_data_rate_is_a_value_error(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock, rate: int
) -> None:
    with pytest.raises(ValueError, match="data rate"):
        ADS1115(bus, data_rate_sps=rate, clock=clock)


def test_channel_outside_0_to_3_is_a_value_error(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    with pytest.raises(ValueError, match="channel 4"):
        ADS1115(bus, clock=clock).read_volts(4)


def test_missing_chip_raises_device_error_naming_chip_and_address(
    bus: SimI2CBus, clock: VirtualClock
) -> None:
    with pytest.raises(DeviceError, match=r"ADS1115 not found at I2C 0x49"):
        ADS1115(bus, address=0x49, clock=clock)


def test_an_oscillator_at_the_slow_end_of_its_tolerance_still_reads(
    bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip = SimADS1115(clock, conversion_time_factor=1.1)
    bus.attach(chip)
    chip.set_input_volts(0, 1.0)
    assert ADS1115(bus, clock=clock).read_volts(0) == pytest.approx(1.0, abs=1e-3)


def test_a_conversion_that_never_finishes_is_a_device_error(
    bus: SimI2CBus, clock: VirtualClock
) -> None:
    bus.attach(SimADS1115(clock, conversion_time_factor=5.0))
    adc = ADS1115(bus, clock=clock)
    with pytest.raises(DeviceError, match=r"ADS1115 at I2C 0x48: conversion on AIN0 not done"):
        adc.read_volts(0)


def test_squeezing_an_fsr_reads_as_newtons_through_the_calibration(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock
) -> None:
    calibration = ForceCalibration(
        [(0.0, 0.0)] + [(fsr406_volts(force), force) for force in (0.2, 0.5, 1.0, 2.0, 5.0, 10.0)]
    )
    adc = ADS1115(bus, clock=clock)

    chip.set_input_volts(0, fsr406_volts(0.0))
    assert calibration.newtons(adc.read_volts(0)) == 0.0

    chip.set_input_volts(0, fsr406_volts(5.0))
    assert calibration.newtons(adc.read_volts(0)) == pytest.approx(5.0, rel=0.01)


def test_calibration_interpolates_between_points_and_clamps_outside() -> None:
    calibration = ForceCalibration([(0.0, 0.0), (1.0, 2.0), (3.0, 10.0)])
    assert calibration.newtons(0.5) == 1.0
    assert calibration.newtons(1.0) == 2.0
    assert calibration.newtons(2.5) == 8.0
    assert calibration.newtons(-0.2) == 0.0
    assert calibration.newtons(3.3) == 10.0


def test_calibration_allows_a_dead_zone_of_equal_forces() -> None:
    calibration = ForceCalibration([(0.0, 0.0), (0.8, 0.0), (2.0, 5.0)])
    assert calibration.newtons(0.5) == 0.0
    assert calibration.newtons(1.4) == pytest.approx(2.5)


@pytest.mark.parametrize(
    ("points", "complaint"),
    [
        ([], "at least two"),
        ([(1.0, 1.0)], "at least two"),
        ([(0.0, 0.0), (0.0, 1.0)], "strictly increasing"),
        ([(1.0, 0.0), (0.5, 1.0)], "strictly increasing"),
        ([(0.0, 2.0), (1.0, 1.0)], "must not decrease"),
        ([(0.0, -1.0), (1.0, 1.0)], "negative force"),
        ([(0.0, 0.0), (float("nan"), 1.0)], "not finite"),
        ([(0.0, 0.0), (1.0,)], "not a \\(volts, newtons\\) pair"),
    ],
)
def test_bad_calibration_tables_are_value_errors(
    points: list[tuple[float, float]], complaint: str
) -> None:
    with pytest.raises(ValueError, match=complaint):
        ForceCalibration(points)


def test_fsr406_volts_rise_with_force() -> None:
    forces = [0.0, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 100.0]
    volts = [fsr406_volts(force) for force in forces]
    assert volts == sorted(volts)
    assert volts[0] == 0.0  # open below the 0.2 N actuation force
    assert volts[2] == pytest.approx(3.3 * 10 / 40)  # 30 kOhm at 0.2 N
    assert volts[5] == pytest.approx(3.3 * 10 / 16)  # 6 kOhm at 1 N
    assert all(0.0 <= v < 3.3 for v in volts)


def test_fsr406_volts_follow_the_divider_and_refuse_nonsense() -> None:
    assert fsr406_volts(1.0, supply_v=5.0, divider_ohm=6_000) == pytest.approx(2.5)
    with pytest.raises(ValueError, match="force"):
        fsr406_volts(-1.0)
    with pytest.raises(ValueError, match="divider"):
        fsr406_volts(1.0, divider_ohm=0)


def test_garbage_never_becomes_a_force(
    chip: SimADS1115, bus: SimI2CBus, clock: VirtualClock, read_garbage: Callable[..., Any]
) -> None:
    # Random bytes cannot echo the config register that was written: every one refused.
    adc = ADS1115(bus, clock=clock)
    readings = read_garbage(bus, 0x48, lambda: adc.read_volts(0), times=50)
    assert readings.believed == []
    assert "ADS1115 at I2C 0x48: config register" in str(readings.refused[0])


def test_a_single_ended_input_cannot_read_below_its_absolute_maximum_under_ground() -> None:
    # -0.3 V is the inputs' absolute maximum below GND: lower codes are refused.
    assert lowest_single_ended_code(4.096) == -2400
    assert lowest_single_ended_code(6.144) == -1600
    assert lowest_single_ended_code(0.256) == -32768  # -0.3 V is beyond full scale: any code
