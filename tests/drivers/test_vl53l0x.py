"""The VL53L0X driver against its simulated chip: ranging, identity, timing, re-addressing."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from engine.clock import VirtualClock
from engine.drivers.vl53l0x import VL53L0X, signal_rate_limit_to_register
from engine.drivers.vl53l0x_results import decode_range, device_range_status
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus, SimI2CDevice
from engine.sim.vl53l0x import SimVL53L0X


@pytest.fixture
def chip(clock: VirtualClock, bus: SimI2CBus) -> SimVL53L0X:
    return SimVL53L0X(clock, bus)


class NotAVL53L0X(SimI2CDevice):
    """Some other chip that answers 0x00 everywhere."""

    def write(self, data: bytes) -> None:
        pass

    def read(self, length: int) -> bytes:
        return bytes(length)


# -- ranging ----------------------------------------------------------------------------------
def test_a_hand_30_cm_away_reads_300_mm(clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 300
    assert sensor.read_range_mm() == 300


def test_a_person_walking_closer_reads_shrinking_distances(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    readings = []
    for distance in (900, 600, 350):
        chip.distance_mm = distance
        readings.append(sensor.read_range_mm())
    assert readings == [900, 600, 350]


def test_nothing_in_front_reads_none(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = None
    assert sensor.read_range_mm() is None


def test_a_wall_beyond_the_sensors_range_reads_none(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 3000  # further than the ~1.2 m of the default mode
    assert sensor.read_range_mm() is None


def test_a_measurement_takes_the_timing_budget_on_the_clock(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 500
    started = clock.now()
    sensor.read_range_mm()
    assert clock.now() - started >= 0.033


def test_the_result_is_not_ready_until_33_ms_have_passed(clock, bus, chip):
    VL53L0X(bus, clock=clock)
    chip.distance_mm = 250
    bus.write_byte_data(0x29, 0x0B, 0x01)  # clear any interrupt
    bus.write_byte_data(0x29, 0x00, 0x01)  # SYSRANGE_START: single shot
    assert bus.read_byte_data(0x29, 0x00) & 0x01 == 0  # start bit cleared: ranging began
    clock.advance(0.032)
    assert bus.read_byte_data(0x29, 0x13) & 0x07 == 0  # still measuring
    clock.advance(0.0015)
    assert bus.read_byte_data(0x29, 0x13) & 0x07 == 0x04  # new sample ready
    high, low = bus.read_i2c_block_data(0x29, 0x1E, 2)
    assert (high << 8) | low == 250  # big-endian


def test_reading_clears_the_interrupt(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 400
    sensor.read_range_mm()
    assert chip.peek(0x13) == 0


def test_a_chip_that_never_finishes_times_out_naming_the_address(clock, bus):
    SimVL53L0X(clock, bus, timing_budget_s=5.0)
    # The calibrations at init are quick; the slow part is ranging itself.
    sensor = VL53L0X(bus, clock=clock, timeout_s=0.1)
    with pytest.raises(DeviceError, match=r"VL53L0X at 0x29: ranging did not finish within 0.1 s"):
        sensor.read_range_mm()


# -- identity and init -------------------------------------------------------------------------
def test_wrong_identity_raises_device_error_naming_chip_and_address(clock, bus):
    bus.attach(NotAVL53L0X(0x29))
    with pytest.raises(DeviceError, match=r"VL53L0X at 0x29.*0x00 0x00 0x00.*not a VL53L0X"):
        VL53L0X(bus, clock=clock)


def test_no_chip_raises_device_error_naming_chip_and_address(clock, bus):
    with pytest.raises(DeviceError, match=r"VL53L0X at 0x29 did not answer"):
        VL53L0X(bus, clock=clock)


def test_init_sets_2v8_io_signal_rate_limit_and_sequence(clock, bus, chip):
    VL53L0X(bus, clock=clock, signal_rate_limit_mcps=0.5)
    assert chip.peek(0x89) & 0x01  # 2V8 I/O
    assert chip.peek(0x60) == 0x00  # MSRC_CONFIG_CONTROL as ST's tuning table leaves it
    assert (chip.peek(0x44) << 8) | chip.peek(0x45) == 64  # 0.5 MCPS in Q9.7, after the table
    assert chip.peek(0x0A) == 0x04  # interrupt on new sample ready
    assert chip.peek(0x01) == 0xE8  # DSS, pre-range, final range


def test_the_nvm_answers_sts_handshake_only_once_switched_on(clock, bus, chip):
    def strobe(word: int) -> int:
        bus.write_byte_data(0x29, 0xFF, 0x07)
        bus.write_byte_data(0x29, 0x94, word)  # which NVM word
        bus.write_byte_data(0x29, 0x83, 0x00)  # the read strobe
        return bus.read_byte_data(0x29, 0x83)  # non-zero: read done

    assert strobe(0x6B) == 0  # NVM access not enabled: the strobe never completes
    bus.write_byte_data(0x29, 0xFF, 0x06)
    bus.write_byte_data(0x29, 0x83, 0x04)  # page 6: enable NVM access
    bus.write_byte_data(0x29, 0xFF, 0x07)
    bus.write_byte_data(0x29, 0x81, 0x01)  # page 7: NVM on
    assert strobe(0x6B) != 0
    assert bus.read_i2c_block_data(0x29, 0x90, 4) == [0x00, 0x00, 0x85, 0x00]  # 5, aperture
    strobe(0x24)
    assert bus.read_i2c_block_data(0x29, 0x90, 4) == [0xFF, 0xDF, 0xFF, 0xFF]  # SPAD 13 bad
    bus.write_byte_data(0x29, 0xFF, 0x00)
    assert bus.read_i2c_block_data(0x29, 0xB0, 6) == [0xFF, 0xDF, 0xFF, 0xFF, 0xFF, 0x3F]


def test_each_measurement_writes_back_the_stop_variable(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 100
    sensor.read_range_mm()
    assert chip.peek(0x91, private_page=True) == 0x3C


# -- addresses and XSHUT -----------------------------------------------------------------------
def test_set_address_moves_the_chip_on_the_bus(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 700
    sensor.set_address(0x30)
    assert bus.addresses == [0x30]
    assert sensor.address == 0x30
    assert sensor.read_range_mm() == 700


@pytest.mark.parametrize("address", [0x00, 0x07, 0x78, 0x80])
def test_set_address_rejects_unusable_addresses(clock, bus, chip, address):
    sensor = VL53L0X(bus, clock=clock)
    with pytest.raises(ValueError, match=f"0x{address:02X}"):
        sensor.set_address(address)


def test_xshut_low_silences_the_chip_and_forgets_its_address(clock, bus, chip):
    sensor = VL53L0X(bus, clock=clock)
    sensor.set_address(0x31)
    chip.set_xshut(False)
    assert bus.addresses == []
    with pytest.raises(OSError):
        bus.read_byte_data(0x31, 0xC0)
    chip.set_xshut(True)
    assert bus.addresses == [0x29]
    with pytest.raises(OSError):  # still booting: no acknowledge
        bus.read_byte_data(0x29, 0xC0)
    clock.advance(0.002)
    assert bus.read_byte_data(0x29, 0xC0) == 0xEE


# -- pure conversions ---------------------------------------------------------------------------
def test_range_decoding():
    valid = 11 << 3
    assert device_range_status(valid) == 11
    assert decode_range(valid, 1234) == 1234
    assert decode_range(valid, 8190) is None
    assert decode_range(valid, 8191) is None
    assert decode_range(4 << 3, 20) is None  # a failure status is no reading
    assert decode_range(8 << 3, 8190) == 0  # too close to range: right at the sensor
    assert decode_range(10 << 3, 20) == 0


def test_signal_rate_limit_is_q9_7():
    assert signal_rate_limit_to_register(0.25) == 32
    assert signal_rate_limit_to_register(0.1) == 13
    with pytest.raises(ValueError, match="-1"):
        signal_rate_limit_to_register(-1)
    with pytest.raises(ValueError, match="512"):
        signal_rate_limit_to_register(512)


def test_garbage_never_becomes_a_valid_distance_past_two_metres(
    clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X, read_garbage: Callable[..., Any]
) -> None:
    sensor = VL53L0X(bus, clock=clock)
    readings = read_garbage(bus, 0x29, sensor.read_range_mm)
    assert readings.refused
    assert all(mm is None or 0 <= mm <= 2000 for mm in readings.believed)
    assert any("VL53L0X at I2C 0x29: range with a valid status" in str(r) for r in readings.refused)


class GarbledAt(SimVL53L0X):
    """A VL53L0X whose bus garbles one register of page 0: it always reads 0xFF."""

    def __init__(self, clock: VirtualClock, bus: SimI2CBus, register: int) -> None:
        super().__init__(clock, bus)
        self.garbled = register

    def read(self, length: int) -> bytes:
        if self._pointer == self.garbled and not self._page:
            self._pointer = (self._pointer + length) & 0xFF
            return b"\xff" * length
        return super().read(length)


@pytest.mark.parametrize(
    ("register", "named"),
    [(0x50, "register 0x50"), (0x70, "register 0x70"), (0x71, "register 0x71")],
)
def test_a_garbled_timing_register_is_a_device_error_never_a_budget(
    clock: VirtualClock, bus: SimI2CBus, register: int, named: str
) -> None:
    """One byte read as 0xFF during bring-up: a VCSEL period no chip has (it divided by
    zero), or a timeout of 10^74 s (it became the budget)."""
    GarbledAt(clock, bus, register)
    with pytest.raises(DeviceError, match=rf"VL53L0X at 0x29: .*{named} reads 0xff"):
        VL53L0X(bus, clock=clock)


def managed(clock: VirtualClock, bus: SimI2CBus) -> tuple[VL53L0X, Any]:
    """A driver on the bus manager, as a poller makes it, and its device handle."""
    from engine.drivers.bus_manager import BusManager
    from engine.hardware.managed_buses import ManagedI2C

    manager: BusManager[SimI2CBus] = BusManager(bus, name="1", clock=clock, threaded=False)
    handle = manager.claim("tof", 0x29)
    return VL53L0X(ManagedI2C(handle), clock=clock), handle


def test_a_reading_through_the_bus_manager_is_five_transactions_with_every_write_in_order(
    clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X
) -> None:
    """Issue 24 (an idle robot): the writes before a measurement go as one transaction of
    the bus manager, and the chip is first asked about the measurement near the end of its
    timing budget; the chip sees the same register writes, in the same order."""
    sensor, handle = managed(clock, bus)
    chip.distance_mm = 420
    before = handle.stats().transactions
    assert sensor.read_range_mm() == 420
    # the writes (page, stop variable, page back, clear, start), the start bit, the
    # interrupt, the result, the clear
    assert handle.stats().transactions - before == 5


# -- ranging back to back (issue 24: a poll that does not wait for a measurement) -------------
def test_ranging_back_to_back_a_poll_reads_the_latest_distance_at_once_in_two_transactions(
    clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X
) -> None:
    sensor, handle = managed(clock, bus)
    chip.distance_mm = 800
    sensor.start_continuous()
    assert sensor.read_range_mm() == 800  # the first waits for the first measurement
    for distance in (650, 400, None):  # someone walks up, then away
        chip.distance_mm = distance
        clock.advance(0.1)  # the poller's period
        started, before = clock.now(), handle.stats().transactions
        assert sensor.read_range_mm() == distance
        assert clock.now() == started  # no wait: a measurement was ready
        assert handle.stats().transactions - before == 2  # status with result, the clear


def test_ranging_back_to_back_a_second_read_waits_for_a_new_measurement(
    clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X
) -> None:
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 500
    sensor.start_continuous()
    sensor.read_range_mm()
    chip.distance_mm = 300
    started = clock.now()
    assert sensor.read_range_mm() == 300  # never the measurement already read
    assert 0 < clock.now() - started <= chip.timing_budget_s + 0.002


def test_a_chip_that_stops_ranging_back_to_back_times_out_naming_the_address(
    clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X
) -> None:
    """A chip reset by a glitch ranges no more: the poll fails (the device goes offline
    and is brought up again), it never passes on an old distance."""
    sensor = VL53L0X(bus, clock=clock)
    chip.distance_mm = 500
    sensor.start_continuous()
    assert sensor.read_range_mm() == 500
    bus.write_byte_data(0x29, 0x00, 0x00)  # SYSRANGE_START: ranging stopped
    clock.advance(0.5)
    with pytest.raises(DeviceError, match=r"VL53L0X at 0x29: ranging continuously, no meas"):
        sensor.read_range_mm()


def test_stopping_back_to_back_ranging_returns_to_single_shots(
    clock: VirtualClock, bus: SimI2CBus, chip: SimVL53L0X
) -> None:
    sensor = VL53L0X(bus, clock=clock)
    sensor.start_continuous()
    sensor.read_range_mm()
    sensor.stop_continuous()
    counted = chip.measurements
    clock.advance(1.0)
    assert chip.peek(0x13) == 0 and chip.measurements == counted  # not ranging
    chip.distance_mm = 250
    started = clock.now()
    assert sensor.read_range_mm() == 250
    assert clock.now() - started >= chip.timing_budget_s  # a single shot again
