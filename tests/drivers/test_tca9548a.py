"""The TCA9548A multiplexer driver against its simulated chip, with VL53L0X behind it."""

from __future__ import annotations

import threading

import pytest

from engine.clock import VirtualClock
from engine.drivers.tca9548a import TCA9548A, channel_mask
from engine.drivers.vl53l0x import VL53L0X
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.tca9548a import SimTCA9548A
from engine.sim.vl53l0x import SimVL53L0X
from engine.sim.zx_gesture import SimZXGesture


@pytest.fixture
def upstream(clock: VirtualClock) -> SimI2CBus:
    return SimI2CBus(clock)


@pytest.fixture
def channels(clock: VirtualClock) -> list[SimI2CBus]:
    return [SimI2CBus(clock, bus_number=10 + n) for n in range(8)]


@pytest.fixture
def sim_mux(upstream: SimI2CBus, channels: list[SimI2CBus]) -> SimTCA9548A:
    return SimTCA9548A(0x70, channels, upstream=upstream)


def test_three_sensors_at_0x29_behind_the_mux_each_read_their_own_distance(
    clock, upstream, channels, sim_mux
):
    chips = [SimVL53L0X(clock, channels[n]) for n in range(3)]
    for chip, distance in zip(chips, (120, 480, 1000), strict=True):
        chip.distance_mm = distance
    mux = TCA9548A(upstream, address=0x70)

    sensors = [VL53L0X(mux.channel_bus(n), clock=clock) for n in range(3)]

    assert [sensor.read_range_mm() for sensor in sensors] == [120, 480, 1000]
    assert all(sensor.address == 0x29 for sensor in sensors)


def test_select_connects_one_channel_by_its_bit(upstream, sim_mux):
    mux = TCA9548A(upstream, address=0x70)
    mux.select(5)
    assert sim_mux.control == 0b0010_0000
    assert mux.selected() == [5]
    mux.deselect_all()
    assert sim_mux.control == 0


def test_a_chip_behind_an_unselected_channel_does_not_answer(clock, upstream, channels, sim_mux):
    channels[2].attach(SimZXGesture(clock))
    mux = TCA9548A(upstream)
    mux.select(1)
    with pytest.raises(OSError):
        upstream.read_byte_data(0x10, 0xFF)
    mux.select(2)
    assert upstream.read_byte_data(0x10, 0xFF) == 0x01


def test_the_mux_keeps_the_last_byte_of_a_multi_byte_write(upstream, sim_mux):
    upstream.write_i2c_block_data(0x70, 0x01, [0x02, 0x04])
    assert sim_mux.control == 0x04
    assert upstream.read_byte(0x70) == 0x04


def test_a_sensor_readdressed_behind_the_mux_is_followed(clock, upstream, channels, sim_mux):
    chip = SimVL53L0X(clock, channels[3])
    chip.distance_mm = 640
    mux = TCA9548A(upstream)
    sensor = VL53L0X(mux.channel_bus(3), clock=clock)
    sensor.set_address(0x33)
    assert channels[3].addresses == [0x33]
    assert sensor.read_range_mm() == 640


def test_two_threads_on_two_channels_never_reach_each_others_chip(
    clock, upstream, channels, sim_mux
):
    for n, address in ((0, 0x10), (1, 0x10)):
        channels[n].attach(SimZXGesture(clock, address, model=0x01 + n))
    mux = TCA9548A(upstream)
    buses = [mux.channel_bus(0), mux.channel_bus(1)]
    seen: list[list[int]] = [[], []]

    def poll(n: int) -> None:
        for _ in range(300):
            seen[n].append(buses[n].read_byte_data(0x10, 0xFF))

    threads = [threading.Thread(target=poll, args=(n,)) for n in (0, 1)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()

    assert set(seen[0]) == {0x01}
    assert set(seen[1]) == {0x02}


def test_a_missing_mux_raises_device_error_naming_it(upstream):
    with pytest.raises(DeviceError, match=r"TCA9548A at 0x71 did not answer"):
        TCA9548A(upstream, address=0x71)


def test_address_and_channel_ranges(upstream, sim_mux):
    with pytest.raises(ValueError, match="0x6F"):
        TCA9548A(upstream, address=0x6F)
    mux = TCA9548A(upstream)
    with pytest.raises(ValueError, match="got 8"):
        mux.select(8)
    with pytest.raises(ValueError, match="got -1"):
        mux.channel_bus(-1)
    assert channel_mask(7) == 0x80


def test_after_the_mux_was_reset_a_failed_read_selects_the_channel_again(
    clock, upstream, channels, sim_mux
):
    channels[0].attach(SimZXGesture(clock))
    mux = TCA9548A(upstream)
    bus0 = mux.channel_bus(0)
    assert bus0.read_byte_data(0x10, 0xFF) == 0x01
    sim_mux.reset()  # a glitch on the RESET pin: nothing connected any more
    with pytest.raises(OSError):
        bus0.read_byte_data(0x10, 0xFF)
    assert bus0.read_byte_data(0x10, 0xFF) == 0x01
    assert sim_mux.control == 0x01


def test_a_mux_made_without_a_check_selects_its_channel_at_the_first_transfer(
    clock, upstream, channels
):
    SimVL53L0X(clock, channels[2])
    answers: list[bool] = []
    mux = TCA9548A(
        upstream, address=0x70, check=False, on_answer=lambda ok, why: answers.append(ok)
    )
    behind = mux.channel_bus(2)
    with pytest.raises(OSError):  # the mux is not there yet: an ordinary bus error
        behind.read_byte_data(0x29, 0xC0)

    SimTCA9548A(0x70, channels, upstream=upstream)  # now it is

    assert behind.read_byte_data(0x29, 0xC0) == 0xEE
    assert answers == [False, True]
