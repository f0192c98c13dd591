"""The PCA9685 driver against its simulated chip: frequency, duty cycles, datasheet rules."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.pca9685 import (
    PCA9685,
    counts_to_duty,
    duty_to_counts,
    frequency_range_hz,
    prescale_for,
)
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.pca9685 import SimPCA9685


@pytest.fixture
def chip(clock: VirtualClock, bus: SimI2CBus) -> SimPCA9685:
    return bus.attach(SimPCA9685(clock))  # type: ignore[return-value]


@pytest.fixture
def pwm(clock: VirtualClock, bus: SimI2CBus, chip: SimPCA9685) -> PCA9685:
    return PCA9685(bus, clock=clock)


# -- frequency ----------------------------------------------------------------------------------
def test_prescale_values_from_the_datasheet_formula():
    assert prescale_for(50) == 121
    assert prescale_for(1000) == 5
    assert prescale_for(200) == 30  # the power-on value
    assert prescale_for(24) == 253
    assert prescale_for(1526) == 3
    assert frequency_range_hz() == (24.0, 1526.0)


@pytest.mark.parametrize("frequency_hz", [23.0, 1527.0, 0.0, -50.0])
def test_frequencies_outside_24_to_1526_hz_are_refused(pwm, frequency_hz):
    with pytest.raises(ValueError, match=r"24\.\.1526 Hz"):
        pwm.set_frequency_hz(frequency_hz)


def test_50_hz_reaches_the_outputs(chip, pwm):
    pwm.set_frequency_hz(50)
    assert chip.prescale == 121
    assert chip.frequency_hz == pytest.approx(50.0, rel=0.01)
    assert pwm.frequency_hz == pytest.approx(50.0, rel=0.01)


def test_1000_hz_reaches_the_outputs(chip, pwm):
    pwm.set_frequency_hz(1000)
    assert chip.prescale == 5
    assert chip.frequency_hz == pytest.approx(1017.25, rel=1e-3)


def test_prescale_written_while_awake_is_ignored(bus, chip, pwm):
    bus.write_byte_data(0x40, 0xFE, 121)  # skipping the sleep the datasheet requires
    assert chip.prescale == 30
    assert chip.frequency_hz == pytest.approx(196.9, rel=1e-3)  # still the power-on 200 Hz


def test_the_chip_loads_at_least_3_into_prescale(bus, chip):
    bus.write_byte_data(0x40, 0x00, 0x10)  # SLEEP
    bus.write_byte_data(0x40, 0xFE, 1)
    assert chip.prescale == 3


def test_changing_frequency_keeps_a_lit_channel_lit(clock, chip, pwm):
    pwm.set_duty(3, 0.5)
    pwm.set_frequency_hz(100)
    assert chip.duty(3) == 0.5
    assert chip.peek(0x00) & 0x80 == 0  # RESTART done


def test_sleep_darkens_the_outputs_until_restart(clock, bus, chip, pwm):
    pwm.set_duty(0, 0.25)
    bus.write_byte_data(0x40, 0x00, 0x30)  # AI | SLEEP with a channel running
    assert chip.duty(0) == 0.0
    assert bus.read_byte_data(0x40, 0x00) & 0x80  # RESTART set
    bus.write_byte_data(0x40, 0x00, 0x20)  # wake
    clock.advance(0.0001)
    bus.write_byte_data(0x40, 0x00, 0xA0)  # RESTART too early: the oscillator is not stable
    clock.advance(0.001)
    assert chip.duty(0) == 0.0
    bus.write_byte_data(0x40, 0x00, 0xA0)
    assert chip.duty(0) == 0.25


# -- duty cycles ----------------------------------------------------------------------------------
def test_half_duty_uses_the_counts(chip, pwm):
    pwm.set_duty(0, 0.5)
    assert [chip.peek(0x06 + i) for i in range(4)] == [0x00, 0x00, 0x00, 0x08]  # OFF = 2048
    assert chip.duty(0) == 0.5
    assert pwm.duty(0) == 0.5


def test_full_duty_uses_the_full_on_bit(chip, pwm):
    pwm.set_duty(15, 1.0)
    assert chip.peek(0x42 + 1) & 0x10  # LED15_ON_H full on
    assert chip.peek(0x42 + 3) & 0x10 == 0
    assert chip.duty(15) == 1.0
    assert pwm.duty(15) == 1.0


def test_zero_duty_uses_the_full_off_bit(chip, pwm):
    pwm.set_duty(7, 1.0)
    pwm.set_duty(7, 0.0)
    assert chip.peek(0x06 + 4 * 7 + 3) & 0x10  # LED7_OFF_H full off
    assert chip.duty(7) == 0.0
    assert pwm.duty(7) == 0.0


def test_all_off_darkens_every_channel(chip, pwm):
    for channel in range(16):
        pwm.set_duty(channel, 0.75)
    pwm.all_off()
    assert [chip.duty(channel) for channel in range(16)] == [0.0] * 16


def test_init_darkens_a_chip_left_lit_by_an_earlier_run(clock, bus, chip, pwm):
    pwm.set_duty(2, 1.0)
    PCA9685(bus, clock=clock)
    assert chip.duty(2) == 0.0


def test_block_writes_auto_increment_only_with_mode1_ai(bus, chip, pwm):
    bus.write_i2c_block_data(0x40, 0x06, [0x01, 0x00, 0x00, 0x04])
    assert [chip.peek(0x06 + i) for i in range(4)] == [0x01, 0x00, 0x00, 0x04]
    bus.write_byte_data(0x40, 0x00, 0x00)  # AI off
    bus.write_i2c_block_data(0x40, 0x0A, [0x11, 0x00, 0x22, 0x03])
    assert chip.peek(0x0A) == 0x03  # every byte landed on LED1_ON_L; the last one stayed
    assert [chip.peek(0x0B + i) for i in range(3)] == [0x00, 0x00, 0x10]


def test_auto_increment_rolls_over_from_led15_to_mode1(bus, chip, pwm):
    data = bus.read_i2c_block_data(0x40, 0x44, 3)  # LED15_OFF_L, LED15_OFF_H, MODE1
    assert data[2] == chip.peek(0x00)


def test_reserved_registers_are_not_acknowledged(bus, chip):
    with pytest.raises(OSError):
        bus.read_byte_data(0x40, 0x50)


def test_all_led_registers_read_zero(bus, chip, pwm):
    pwm.all_off()
    assert bus.read_byte_data(0x40, 0xFD) == 0


@pytest.mark.parametrize("channel", [-1, 16])
def test_channels_outside_0_to_15_are_refused(pwm, channel):
    with pytest.raises(ValueError, match=f"got {channel}"):
        pwm.set_duty(channel, 0.5)
    with pytest.raises(ValueError, match=f"got {channel}"):
        pwm.duty(channel)


@pytest.mark.parametrize("fraction", [-0.1, 1.01, math.nan])
def test_fractions_outside_0_to_1_are_refused(pwm, fraction):
    with pytest.raises(ValueError, match=r"0\.0\.\.1\.0"):
        pwm.set_duty(0, fraction)


# -- identity ---------------------------------------------------------------------------------
def test_missing_chip_raises_device_error_naming_it(clock, bus):
    with pytest.raises(DeviceError, match=r"PCA9685 at 0x41 did not answer"):
        PCA9685(bus, address=0x41, clock=clock)


def test_address_0x70_is_refused_as_the_all_call_address(clock, bus):
    with pytest.raises(ValueError, match="0x70"):
        PCA9685(bus, address=0x70, clock=clock)


def test_init_turns_all_call_off_and_auto_increment_on(chip, pwm):
    mode1 = chip.peek(0x00)
    assert mode1 & 0x20
    assert mode1 & 0x01 == 0
    assert not chip.sleeping


# -- pure conversions ---------------------------------------------------------------------------
def test_duty_counts_round_trip():
    assert duty_to_counts(0.0) == (0, 0x1000)
    assert duty_to_counts(1.0) == (0x1000, 0)
    assert duty_to_counts(0.5) == (0, 2048)
    assert duty_to_counts(0.0001) == (0, 0x1000)  # under half a count: off
    assert duty_to_counts(0.9999) == (0x1000, 0)  # within half a count of full: on
    for fraction in (0.1, 0.25, 0.333, 0.9):
        assert counts_to_duty(*duty_to_counts(fraction)) == pytest.approx(fraction, abs=1 / 8192)
    assert counts_to_duty(0x1000, 0x1000) == 0.0  # full off wins over full on
    assert counts_to_duty(4000, 100) == pytest.approx(196 / 4096)  # on late, off after wrap


def test_garbage_never_becomes_a_frequency_the_chip_cannot_run_at(
    bus: SimI2CBus, clock: VirtualClock, read_garbage: Callable[..., Any]
) -> None:
    bus.attach(SimPCA9685(clock))
    pwm = PCA9685(bus, clock=clock)
    readings = read_garbage(bus, 0x40, lambda: pwm.frequency_hz, times=500)
    assert readings.refused
    assert all(hz <= 25e6 / (4096 * 4) for hz in readings.believed)
    assert "PCA9685 at I2C 0x40: PRE_SCALE" in str(readings.refused[0])
