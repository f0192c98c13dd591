"""The SRF02 driver against the simulated ranger: someone walks up, steps close, walks away."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.srf02 import MIN_RANGE_CM, SRF02
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.srf02 import SimSRF02

ADDRESS = 0x70


@pytest.fixture
def chip(bus: SimI2CBus, clock: VirtualClock) -> SimSRF02:
    return bus.attach(SimSRF02(clock))  # type: ignore[return-value]


def test_a_person_150_cm_away_reads_150(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    ranger = SRF02(bus, clock=clock)
    chip.distance_cm = 150.4
    before = clock.now()
    assert ranger.read_range_cm() == 150
    assert clock.now() - before == pytest.approx(0.066)


def test_busy_while_ranging_then_the_result_after_66_ms(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip.distance_cm = 80.0
    bus.write_byte_data(ADDRESS, 0x00, 0x51)
    clock.advance(0.030)
    assert bus.read_byte_data(ADDRESS, 0x00) == 0xFF
    assert bus.read_i2c_block_data(ADDRESS, 0x02, 2) == [0, 0]  # previous result kept

    clock.advance(0.036)
    assert bus.read_byte_data(ADDRESS, 0x00) == 6  # software revision: idle again
    assert bus.read_i2c_block_data(ADDRESS, 0x02, 2) == [0, 80]


def test_commands_while_ranging_are_ignored(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip.distance_cm = 254.0
    bus.write_byte_data(ADDRESS, 0x00, 0x51)
    clock.advance(0.010)
    bus.write_byte_data(ADDRESS, 0x00, 0x50)  # inches: the busy chip does not listen
    clock.advance(0.056)
    assert bus.read_i2c_block_data(ADDRESS, 0x02, 2) == [0, 254]


def test_inches_and_microseconds_commands(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    chip.distance_cm = 254.0
    bus.write_byte_data(ADDRESS, 0x00, 0x50)
    clock.advance(0.066)
    assert bus.read_i2c_block_data(ADDRESS, 0x02, 2) == [0, 100]

    bus.write_byte_data(ADDRESS, 0x00, 0x52)
    clock.advance(0.066)
    high, low = bus.read_i2c_block_data(ADDRESS, 0x02, 2)
    assert high << 8 | low == round(254 * 58.3)  # out and back at 343 m/s


def test_the_non_blocking_split_waits_for_the_ranging_time(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    ranger = SRF02(bus, clock=clock)
    chip.distance_cm = 200.0
    ranger.start_ranging()
    transfers = bus.transfers
    clock.advance(0.050)
    assert not ranger.result_ready()
    assert bus.transfers == transfers  # no bus traffic before the ranging time is up
    with pytest.raises(DeviceError, match="still ranging"):
        ranger.read_result_cm()

    clock.advance(0.016)
    assert ranger.result_ready()
    assert ranger.read_result_cm() == 200


def test_closer_than_the_minimum_reads_the_minimum(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    ranger = SRF02(bus, clock=clock)
    chip.distance_cm = 5.0
    # a fresh chip still rings for 28 cm; autotune backs off over the first rangings
    first = ranger.read_range_cm()
    assert first == 28
    readings = [ranger.read_range_cm() for _ in range(8)]
    assert readings == sorted(readings, reverse=True)
    assert readings[-1] == MIN_RANGE_CM == chip.minimum_range_cm

    high, low = bus.read_i2c_block_data(ADDRESS, 0x04, 2)  # autotune minimum register
    assert high << 8 | low == MIN_RANGE_CM


def test_nothing_in_range_reads_zero(chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock) -> None:
    ranger = SRF02(bus, clock=clock)
    chip.distance_cm = None
    assert ranger.read_range_cm() == 0
    chip.distance_cm = 900.0  # beyond the 6 m the sensor hears
    assert ranger.read_range_cm() == 0


def test_a_chip_that_stays_busy_is_a_bounded_device_error(
    bus: SimI2CBus, clock: VirtualClock
) -> None:
    bus.attach(SimSRF02(clock, ranging_time_s=1.0))
    ranger = SRF02(bus, clock=clock, max_polls=3)
    transfers = bus.transfers
    with pytest.raises(DeviceError, match=r"SRF02 at I2C 0x70 still ranging after 0.081 s"):
        ranger.read_range_cm()
    assert bus.transfers - transfers == 1 + 3  # the command, then three polls


def test_a_chip_that_does_not_acknowledge_while_ranging_counts_as_busy(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    ranger = SRF02(bus, clock=clock)
    chip.distance_cm = 120.0
    ranger.start_ranging()
    bus.inject("nack", 0.075, ADDRESS)  # a little longer than the ranging itself
    clock.advance(0.070)
    assert not ranger.result_ready()
    clock.advance(0.005)
    assert ranger.result_ready()
    assert ranger.read_result_cm() == 120


def test_a_chip_gone_for_good_raises_after_the_polling_allowance(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    ranger = SRF02(bus, clock=clock)
    ranger.start_ranging()
    bus.inject("unplugged", 10.0, ADDRESS)
    clock.advance(0.070)
    assert not ranger.result_ready()
    clock.advance(0.100)
    with pytest.raises(OSError):
        ranger.result_ready()


def test_identity_reads_a_revision_and_0x80(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    assert SRF02(bus, clock=clock).software_revision == 6


def test_identity_waits_out_a_ranging_in_progress(
    chip: SimSRF02, bus: SimI2CBus, clock: VirtualClock
) -> None:
    bus.write_byte_data(ADDRESS, 0x00, 0x51)
    assert SRF02(bus, clock=clock).software_revision == 6


def test_missing_chip_raises_device_error_naming_chip_and_address(
    bus: SimI2CBus, clock: VirtualClock
) -> None:
    with pytest.raises(DeviceError, match=r"SRF02 not found at I2C 0x71"):
        SRF02(bus, address=0x71, clock=clock)


def test_garbage_never_becomes_a_range_the_chip_cannot_report(
    chip: SimSRF02, bus: SimI2CBus, read_garbage: Callable[..., Any]
) -> None:
    # "8146 cm away" must never be said: the SRF02 reports 0 (no echo) or 15..600 cm.
    ranger = SRF02(bus, clock=bus.clock)
    readings = read_garbage(bus, 0x70, ranger.read_range_cm)
    assert readings.refused
    assert all(cm == 0 or 15 <= cm <= 600 for cm in readings.believed)
    assert "SRF02 at I2C 0x70: range" in str(readings.refused[0])
