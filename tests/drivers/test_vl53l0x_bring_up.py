"""Our VL53L0X driver brings a chip up as ST does, held against Adafruit's driver.

Both drivers bring up a simulated chip of their own, on a bus that records every write
transfer; the register writes must be the same, in the same order, but for the
differences listed below with their reasons. Reads are not compared: how a driver learns
a value is its own business, what it writes is what the chip ends up doing. The
bring-up's own failures (an NVM that never answers, or answers nonsense, a NACK in the
middle) fail safe: a DeviceError or the bus's OSError, and the chip left on its main
register page for the next try.
"""

from __future__ import annotations

import errno

import pytest

from engine.clock import VirtualClock
from engine.drivers.vl53l0x import VL53L0X
from engine.drivers.vl53l0x_spads import ReferenceSpads, select_reference_spads
from engine.drivers.vl53l0x_timing import (
    TimingRegisters,
    final_range_timeout_for,
    timing_budget_us,
)
from engine.drivers.vl53l0x_tuning import DEFAULT_TUNING
from engine.errors import DeviceError
from engine.sim.i2c_bus import SimI2CBus, bus_error
from engine.sim.vl53l0x import SimVL53L0X

from .reference_bus import NvmOff, RecordingBus, ReferenceI2C, load_reference_driver

ADDRESS = 0x29

# Our writes that Adafruit's driver does not make, and why (each "REG=VALUE", hex).
IO_2V8 = ["89=01"]
"""First of all, the I/O pads in 2V8 mode (VHV_CONFIG_PAD_SCL_SDA__EXTSUP_HV bit 0), as ST's
DataInit does when built for 2.8 V I/O and Pololu's library by default; Adafruit's driver
leaves the power-on setting (option ``io_2v8=False`` of ours does too)."""
NVM_GOOD_SPAD_MAP_READS = ["94=24", "83=00", "83=01", "94=25", "83=00", "83=01"]
"""After the NVM read of the SPAD count and kind, two more NVM reads (words 0x24 and 0x25)
for the map of working reference SPADs, as ST's ``VL53L0X_get_info_from_device`` does;
Adafruit's driver (after Pololu's) reads that map from GLOBAL_CONFIG_SPAD_ENABLES_REF_0..5
instead, where the chip left it at boot. The SPADs enabled afterwards are the same."""
STALE_RESULT_CLEAR = ["0B=01"]
"""Before starting a measurement, ours clears the interrupt, so that a result left from
before (a measurement a failed read abandoned) never passes for the new one."""


def _writes(bus: RecordingBus) -> list[str]:
    """The register writes to the chip, as "REG=DATA" in hex (16-bit and block writes whole)."""
    return [f"{data[0]:02X}={data[1:].hex().upper()}" for _, data in bus.register_writes(ADDRESS)]


def _registers(chip: SimVL53L0X, page: int) -> list[int]:
    return [chip.peek(register, page=page) for register in range(0xFF)]


@pytest.fixture
def adafruit_vl53l0x(monkeypatch: pytest.MonkeyPatch) -> tuple[RecordingBus, SimVL53L0X, object]:
    """A chip on a recording bus, brought up by Adafruit's driver on a clock of its own."""
    clock = VirtualClock()
    bus = RecordingBus(clock)
    chip = SimVL53L0X(clock, bus)
    driver = load_reference_driver("adafruit_vl53l0x", clock, monkeypatch)
    return bus, chip, driver.VL53L0X(ReferenceI2C(bus, clock))


@pytest.fixture
def our_vl53l0x() -> tuple[RecordingBus, SimVL53L0X, VL53L0X]:
    """A chip on a recording bus, brought up by our driver on a clock of its own."""
    clock = VirtualClock()
    bus = RecordingBus(clock)
    chip = SimVL53L0X(clock, bus)
    return bus, chip, VL53L0X(bus, clock=clock)


def test_our_bring_up_writes_what_adafruits_writes_but_for_the_listed_differences(
    adafruit_vl53l0x: tuple[RecordingBus, SimVL53L0X, object],
    our_vl53l0x: tuple[RecordingBus, SimVL53L0X, VL53L0X],
) -> None:
    theirs, ours = _writes(adafruit_vl53l0x[0]), _writes(our_vl53l0x[0])
    end_of_spad_info_read = theirs.index("83=01") + 1  # their one NVM read, strobe done

    expected = [
        *IO_2V8,
        *theirs[:end_of_spad_info_read],
        *NVM_GOOD_SPAD_MAP_READS,
        *theirs[end_of_spad_info_read:],
    ]
    assert ours == expected
    # The parts that matter are all in there, in ST's order: the SPAD map, the whole
    # tuning table, the ~33 ms budget's final-range timeout, both calibrations.
    tuning = [f"{register:02X}={value:02X}" for register, value in DEFAULT_TUNING]
    start = ours.index("B0=00D003000000")
    assert ours[start + 1 : start + 1 + len(tuning)] == tuning
    budget_and_calibrations = [
        "01=E8",  # the sequence without TCC and MSRC...
        "71=0294",  # ...and the final range given the time they took
        *("01=01", "00=41", "0B=01", "00=00"),  # VHV calibration
        *("01=02", "00=01", "0B=01", "00=00"),  # phase calibration
        "01=E8",
    ]
    assert ours[-len(budget_and_calibrations) :] == budget_and_calibrations


def test_both_bring_ups_leave_the_chip_in_the_same_state(
    adafruit_vl53l0x: tuple[RecordingBus, SimVL53L0X, object],
    our_vl53l0x: tuple[RecordingBus, SimVL53L0X, VL53L0X],
) -> None:
    their_chip, our_chip = adafruit_vl53l0x[1], our_vl53l0x[1]
    for page in (0, 1):  # the documented map and the private page
        theirs, ours = _registers(their_chip, page), _registers(our_chip, page)
        if page == 0:
            ours[0x89] &= ~0x01  # IO_2V8
        assert ours == theirs


def test_a_measurement_writes_what_adafruits_writes_but_for_the_stale_result_clear(
    adafruit_vl53l0x: tuple[RecordingBus, SimVL53L0X, object],
    our_vl53l0x: tuple[RecordingBus, SimVL53L0X, VL53L0X],
) -> None:
    their_bus, their_chip, their_sensor = adafruit_vl53l0x
    our_bus, our_chip, our_sensor = our_vl53l0x
    for bus, chip in ((their_bus, their_chip), (our_bus, our_chip)):
        chip.distance_mm = 640
        bus.writes.clear()

    assert their_sensor.range == our_sensor.read_range_mm() == 640  # type: ignore[attr-defined]

    theirs, ours = _writes(their_bus), _writes(our_bus)
    start = theirs.index("80=00") + 1  # SYSRANGE_START, after the stop variable's page dance
    assert ours == [*theirs[:start], *STALE_RESULT_CLEAR, *theirs[start:]]


def test_the_timing_budget_is_sts_and_gives_the_final_range_what_adafruits_gives() -> None:
    after_tuning = TimingRegisters(0xF8, 0x06, 0x25, 0x0096, 0x04, 0x01FE)
    assert timing_budget_us(after_tuning) == 33_849  # Adafruit's rounding makes it 33 971 us
    without_tcc = TimingRegisters(0xE8, 0x06, 0x25, 0x0096, 0x04, 0x01FE)
    assert final_range_timeout_for(without_tcc, 33_849) == 0x0294  # Adafruit's value too
    with pytest.raises(ValueError, match="at least 20000 us"):
        final_range_timeout_for(without_tcc, 19_999)


def test_our_driver_knows_its_timing_budget(
    our_vl53l0x: tuple[RecordingBus, SimVL53L0X, VL53L0X],
) -> None:
    assert our_vl53l0x[2].timing_budget_s == pytest.approx(0.033849)


# -- reference SPADs from the NVM ----------------------------------------------------------------
def test_aperture_spads_start_at_the_thirteenth_and_skip_the_bad_ones() -> None:
    spads = ReferenceSpads(5, True, bytes([0xFF, 0xDF, 0xFF, 0xFF, 0xFF, 0x3F]))
    assert select_reference_spads(spads) == bytes([0x00, 0xD0, 0x03, 0x00, 0x00, 0x00])


def test_non_aperture_spads_come_from_the_first_twelve() -> None:
    spads = ReferenceSpads(3, False, bytes([0b1111_1010, 0x0F, 0, 0, 0, 0]))
    assert select_reference_spads(spads) == bytes([0b0001_1010, 0, 0, 0, 0, 0])


@pytest.mark.parametrize(
    ("count", "aperture", "good_map", "problem"),
    [
        (33, True, b"\xff" * 6, "33 aperture reference SPADs; at most 32"),
        (13, False, b"\xff" * 6, "13 non-aperture reference SPADs; at most 12"),
        (4, False, bytes([0x07, 0xF0, 0xFF, 0xFF, 0xFF, 0xFF]), "its map has 3"),
    ],
)
def test_nvm_spad_data_that_st_would_not_use_is_refused(
    count: int, aperture: bool, good_map: bytes, problem: str
) -> None:
    with pytest.raises(ValueError, match=problem):
        select_reference_spads(ReferenceSpads(count, aperture, good_map))


def test_our_driver_enables_the_non_aperture_spads_a_chip_asks_for(
    clock: VirtualClock, bus: SimI2CBus
) -> None:
    chip = SimVL53L0X(
        clock, bus, spad_count=3, spad_aperture=False, good_spad_map=bytes([0xFA, 0x0F, 0, 0, 0, 0])
    )
    VL53L0X(bus, clock=clock)
    assert [chip.peek(0xB0 + i) for i in range(6)] == [0x1A, 0x00, 0x00, 0x00, 0x00, 0x00]


# -- failing safe ----------------------------------------------------------------------------------
def test_a_chip_whose_nvm_never_answers_is_a_device_error_and_stays_on_its_main_page(
    clock: VirtualClock, bus: SimI2CBus
) -> None:
    NvmOff(clock, bus)
    with pytest.raises(DeviceError, match=r"VL53L0X at 0x29: NVM read 0x6B did not finish"):
        VL53L0X(bus, clock=clock, timeout_s=0.05)
    assert bus.read_byte_data(ADDRESS, 0xC0) == 0xEE  # the identity, where a retry looks


def test_a_chip_whose_nvm_asks_for_too_many_spads_is_refused(
    clock: VirtualClock, bus: SimI2CBus
) -> None:
    SimVL53L0X(clock, bus, spad_count=40)
    with pytest.raises(DeviceError, match=r"VL53L0X at 0x29: NVM asks for 40 aperture"):
        VL53L0X(bus, clock=clock)


class NackInTheNvmHandshake(SimVL53L0X):
    """A chip that does not acknowledge the first write of an NVM word address (a loose
    cable at the worst moment), then behaves."""

    nacked = False

    def write(self, data: bytes) -> None:
        if data[:1] == b"\x94" and not self.nacked:
            self.nacked = True
            raise bus_error(errno.EREMOTEIO, self.address)
        super().write(data)


def test_a_nack_in_the_nvm_handshake_fails_the_bring_up_and_the_next_try_succeeds(
    clock: VirtualClock, bus: SimI2CBus
) -> None:
    chip = NackInTheNvmHandshake(clock, bus)
    with pytest.raises(OSError, match="Remote I/O error"):
        VL53L0X(bus, clock=clock)

    sensor = VL53L0X(bus, clock=clock)  # a retry finds the identity on the main page
    chip.distance_mm = 250
    assert sensor.read_range_mm() == 250
