"""The ZX gesture sensor driver against its simulated chip."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.zx_gesture import ZXGesture, decode_position, gesture_name
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.zx_gesture import SimZXGesture


@pytest.fixture
def chip(clock: VirtualClock, bus: SimI2CBus) -> SimZXGesture:
    return bus.attach(SimZXGesture(clock))  # type: ignore[return-value]


@pytest.fixture
def sensor(bus: SimI2CBus, chip: SimZXGesture) -> ZXGesture:
    return ZXGesture(bus)


def test_a_swipe_is_reported_once_then_none(chip, sensor):
    chip.perform("swipe_left")
    assert sensor.read_gesture() == "swipe_left"
    assert sensor.read_gesture() is None


@pytest.mark.parametrize(
    "gesture",
    ["swipe_right", "swipe_left", "swipe_up", "hover", "hover_left", "hover_right", "hover_up"],
)
def test_every_gesture_the_chip_knows_reaches_the_engine_by_name(chip, sensor, gesture):
    chip.perform(gesture)
    assert sensor.read_gesture() == gesture


def test_a_hover_after_a_swipe_is_a_new_gesture(chip, sensor):
    chip.perform("swipe_right")
    assert sensor.read_gesture() == "swipe_right"
    chip.perform("hover")
    assert sensor.read_gesture() == "hover"
    assert sensor.read_gesture() is None


def test_nothing_happening_reads_no_gesture(sensor):
    assert sensor.read_gesture() is None


def test_a_hand_in_view_has_a_position(clock, chip, sensor):
    chip.hand_at(120, 60)
    assert sensor.read_position() == (120, 60)
    clock.advance(0.05)  # the chip keeps sampling while the hand is there
    assert sensor.read_position() == (120, 60)


def test_a_hand_moving_across_is_followed(clock, chip, sensor):
    positions = []
    for x in (40, 120, 200):
        chip.hand_at(x, 80)
        positions.append(sensor.read_position())
        clock.advance(0.02)
    assert positions == [(40, 80), (120, 80), (200, 80)]


def test_no_hand_no_position(clock, chip, sensor):
    assert sensor.read_position() is None
    chip.hand_at(100, 100)
    sensor.read_position()
    chip.hand_away()
    clock.advance(0.1)
    assert sensor.read_position() is None


def test_reading_the_position_does_not_swallow_a_gesture(chip, sensor):
    # STATUS clears all its flags when read: the swipe flag goes with the position read.
    chip.hand_at(100, 30)
    chip.perform("swipe_up")
    assert sensor.read_position() == (100, 30)
    assert sensor.read_gesture() == "swipe_up"
    assert sensor.read_gesture() is None


def test_status_is_read_to_clear_and_its_heartbeat_toggles(bus, chip):
    chip.perform("hover")
    first = bus.read_byte_data(0x10, 0x00)
    second = bus.read_byte_data(0x10, 0x00)
    assert first & 0x08  # HOVER
    assert second & 0x1D == 0  # every flag cleared
    assert (first ^ second) & 0x80  # heartbeat toggled


def test_wrong_model_raises_device_error_naming_chip_and_address(clock, bus):
    bus.attach(SimZXGesture(clock, 0x11, model=0x07))
    with pytest.raises(DeviceError, match=r"ZX gesture sensor at 0x11: model 0x07"):
        ZXGesture(bus, address=0x11)


def test_missing_sensor_raises_device_error(bus):
    with pytest.raises(DeviceError, match=r"ZX gesture sensor at 0x10 did not answer"):
        ZXGesture(bus)


def test_only_the_two_strapped_addresses_are_accepted(bus):
    with pytest.raises(ValueError, match="0x12"):
        ZXGesture(bus, address=0x12)


def test_the_simulated_hand_stays_in_the_chips_range(chip):
    with pytest.raises(ValueError, match="241"):
        chip.hand_at(241, 0)
    with pytest.raises(ValueError, match="wave"):
        chip.perform("wave")  # the engine's word, not a chip gesture


def test_pure_decoding():
    assert gesture_name(0x02) == "swipe_left"
    assert gesture_name(0x00) is None
    assert gesture_name(0x04) is None  # no gesture has code 4
    assert decode_position(240, 0) == (240, 0)
    assert decode_position(255, 10) is None


def test_a_gesture_the_chip_latched_before_the_driver_started_is_not_reported(bus, chip):
    chip.perform("swipe_right")  # long ago: nobody was reading the sensor then

    sensor = ZXGesture(bus)

    assert sensor.read_gesture() is None
    chip.perform("swipe_left")
    assert sensor.read_gesture() == "swipe_left"


def test_garbage_never_becomes_a_phantom_gesture(
    bus: SimI2CBus, sensor: ZXGesture, read_garbage: Callable[..., Any]
) -> None:
    readings = read_garbage(bus, 0x10, sensor.read_gesture)
    assert readings.refused
    known = {"swipe_right", "swipe_left", "swipe_up", "hover", "hover_left", "hover_right"}
    assert all(g is None or g in known | {"hover_up"} for g in readings.believed)
    assert "ZX gesture sensor at I2C 0x10: gesture code" in str(readings.refused[0])


def test_garbage_never_becomes_a_hand_position_beyond_240(
    bus: SimI2CBus, sensor: ZXGesture, read_garbage: Callable[..., Any]
) -> None:
    readings = read_garbage(bus, 0x10, sensor.read_position)
    assert readings.refused
    assert all(p is None or max(p) <= 240 for p in readings.believed)
