"""A register-level model of the ST VL53L0X time-of-flight sensor.

What it models, as the chip behaves on the wire:

* identity registers 0xC0..0xC2 = 0xEE 0xAA 0x10; an 8-bit register pointer that
  auto-increments, so 16-bit registers read big-endian in one transfer;
* register pages selected by 0xFF: page 0 is the documented map, page 1 the private page
  with the stop variable at 0x91, pages 6 and 7 the NVM access of ST's API; every page
  keeps what is written to it, so ST's default tuning table lands where the chip keeps it;
* the factory NVM (ST's "get info from device" handshake): with bit 2 of register 0x83 set
  on page 6 and register 0x81 = 0x01 on page 7, writing the NVM word address to 0x94 and
  0x00 to 0x83 (the read strobe) loads that 32-bit word big-endian into 0x90..0x93, and
  0x83 then reads non-zero; without those two enables the strobe never completes (0x83
  reads 0, as a chip whose NVM is not switched on). Word 0x6B holds the reference SPAD
  count (bits 14:8) and type (bit 15, aperture), words 0x24 and 0x25 the 6-byte map of
  good reference SPADs;
* the reference SPAD enables GLOBAL_CONFIG_SPAD_ENABLES_REF_0..5 (0xB0..0xB5) boot
  holding that good-SPAD map (Pololu's observation, which Adafruit's driver relies on);
* single-shot ranging: writing bit 0 of SYSRANGE_START starts it (the bit reads back 0
  once ranging has begun, here at once); RESULT_INTERRUPT_STATUS reads 0 for the timing
  budget (~33 ms by default) and then "new sample ready" (0x04) until SYSTEM_INTERRUPT_CLEAR
  is written; RESULT_RANGE_STATUS holds device status 11 (valid) and the range in mm at
  +10, or 8190 and a failure status when nothing is within ``max_range_mm``;
* back-to-back continuous ranging: writing bit 1 of SYSRANGE_START (0x02) starts it; a
  measurement completes every timing budget, each raising "new sample ready" and holding
  its result until the next (whether or not the last was cleared); writing SYSRANGE_START
  without bit 1 ends it (bit 0 then starts a single shot, as before);
* reference calibrations (SYSRANGE_START with SYSTEM_SEQUENCE_CONFIG 0x01 or 0x02): they
  raise the same interrupt after ``CALIBRATION_TIME_S``;
* I2C_SLAVE_DEVICE_ADDRESS (0x8A): the chip moves to the new address on its bus;
* XSHUT: low puts the chip in hardware standby: it leaves the bus (no answer at all) and
  forgets its address and every register; high boots it at 0x29, NACKing for tBOOT.

Simplified: the distance is sampled when ranging starts (ranging continuously: when the
chip is next read or written after a measurement completes); there is no noise, no signal
rate, no SPAD or tuning effect (the chip ranges the same with or without the full ST init,
and takes ``timing_budget_s`` whatever its timing registers say); an NVM read completes at
once; timed continuous ranging (an inter-measurement period) is not modelled; a
calibration's duration is a stand-in (ST does not publish it). The "no target" status is
MSRC no-target (4); a real chip may report another failure code, which the driver treats
alike. ST documents none of the NVM registers: their behaviour here is what ST's API and
Adafruit's driver expect of them.

Two chips cannot share an address on a :class:`SimI2CBus`, so a collision that real
hardware would turn into garbled answers raises ``ValueError`` here (a wiring mistake in
the simulated world, said loudly).
"""

from __future__ import annotations

import errno

from engine.clock import Clock
from engine.drivers.vl53l0x_registers import (
    DEVICE_RANGE_STATUS_MSRC_NO_TARGET,
    DEVICE_RANGE_STATUS_SHIFT,
    DEVICE_RANGE_STATUS_VALID,
    FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT,
    GLOBAL_CONFIG_SPAD_ENABLES_REF_0,
    GPIO_HV_MUX_ACTIVE_HIGH,
    I2C_SLAVE_DEVICE_ADDRESS,
    IDENTIFICATION_MODEL_ID,
    IDENTITY,
    INTERRUPT_NEW_SAMPLE_READY,
    NVM_ADDRESS,
    NVM_CONTROL,
    NVM_DATA,
    NVM_ENABLE,
    NVM_ENABLE_PAGE,
    NVM_GOOD_SPAD_MAP,
    NVM_PAGE,
    NVM_POWER,
    NVM_READ_DONE,
    NVM_SPAD_INFO,
    PAGE_SELECT,
    POWER_ON_ADDRESS,
    PRIVATE_PAGE,
    RANGE_OUT_OF_RANGE_MM,
    RESULT_BLOCK_LENGTH,
    RESULT_INTERRUPT_STATUS,
    RESULT_RANGE_MM,
    RESULT_RANGE_STATUS,
    SEQUENCE_ALL,
    SEQUENCE_PHASE_CALIBRATION,
    SEQUENCE_VHV_CALIBRATION,
    STOP_VARIABLE,
    SYSRANGE_START,
    SYSRANGE_START_BACK_TO_BACK,
    SYSRANGE_START_SINGLESHOT,
    SYSTEM_INTERRUPT_CLEAR,
    SYSTEM_SEQUENCE_CONFIG,
    TBOOT_MAX_S,
)
from engine.sim.i2c_bus import SimI2CBus, SimI2CDevice, bus_error

# A plausible factory calibration: 5 aperture SPADs; reference SPAD 13 is bad.
DEFAULT_SPAD_COUNT = 5
DEFAULT_GOOD_SPAD_MAP = bytes([0xFF, 0xDF, 0xFF, 0xFF, 0xFF, 0x3F])

CALIBRATION_SEQUENCES = {SEQUENCE_VHV_CALIBRATION, SEQUENCE_PHASE_CALIBRATION}
CALIBRATION_TIME_S = 0.001

_POWER_ON_REGISTERS = {
    **{IDENTIFICATION_MODEL_ID + offset: value for offset, value in enumerate(IDENTITY)},
    SYSTEM_SEQUENCE_CONFIG: SEQUENCE_ALL,
    FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT: 0x00,  # high byte
    FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT + 1: 0x20,  # low byte: 0.25 MCPS in Q9.7
    GPIO_HV_MUX_ACTIVE_HIGH: 0x11,
    I2C_SLAVE_DEVICE_ADDRESS: POWER_ON_ADDRESS,
}
_POWER_ON_PRIVATE = {STOP_VARIABLE: 0x3C}  # a plausible stop variable; any value works
_READ_ONLY = {
    *range(IDENTIFICATION_MODEL_ID, IDENTIFICATION_MODEL_ID + len(IDENTITY)),
    RESULT_INTERRUPT_STATUS,
    *range(RESULT_RANGE_STATUS, RESULT_RANGE_STATUS + RESULT_BLOCK_LENGTH),
}


def _factory_nvm(spad_count: int, spad_aperture: bool, good_spad_map: bytes) -> dict[int, int]:
    """The NVM words ST's API reads, by word address (32-bit values)."""
    spad_info = spad_count | (0x80 if spad_aperture else 0x00)
    head = int.from_bytes(good_spad_map[:4], "big")
    tail = int.from_bytes(good_spad_map[4:], "big") << 16
    return {NVM_SPAD_INFO: spad_info << 8, NVM_GOOD_SPAD_MAP[0]: head, NVM_GOOD_SPAD_MAP[1]: tail}


class SimVL53L0X(SimI2CDevice):
    """A VL53L0X soldered onto ``bus``, looking at whatever is ``distance_mm`` away.

    With ``xshut_high`` (the board's pull-up) it is powered and on the bus at once;
    otherwise it waits in hardware standby for :meth:`set_xshut`. ``spad_count``,
    ``spad_aperture`` and ``good_spad_map`` are its factory calibration in NVM (the
    reference SPADs to enable, their type, and which of the 48 reference SPADs work).
    """

    def __init__(
        self,
        clock: Clock,
        bus: SimI2CBus,
        address: int = POWER_ON_ADDRESS,
        *,
        timing_budget_s: float = 0.033,
        max_range_mm: float = 1200.0,
        xshut_high: bool = True,
        spad_count: int = DEFAULT_SPAD_COUNT,
        spad_aperture: bool = True,
        good_spad_map: bytes = DEFAULT_GOOD_SPAD_MAP,
    ) -> None:
        super().__init__(address)
        if not 0 <= spad_count <= 0x7F:
            raise ValueError(f"a VL53L0X NVM holds a SPAD count of 0..127, got {spad_count}")
        if len(good_spad_map) != 6:
            raise ValueError(f"the good reference SPAD map is 6 bytes, got {len(good_spad_map)}")
        self._clock = clock
        self._bus = bus
        self.timing_budget_s = timing_budget_s
        self.max_range_mm = max_range_mm
        self._nvm = _factory_nvm(spad_count, spad_aperture, good_spad_map)
        self._good_spad_map = bytes(good_spad_map)
        self._distance_mm: float | None = None
        self._attached = False
        self._xshut_high = False
        self._power_on_reset()
        self.measurements = 0
        if xshut_high:
            # Powered long before the simulation began, possibly already moved.
            self._xshut_high = True
            self.address = address
            self._registers[I2C_SLAVE_DEVICE_ADDRESS] = address
            self._attach()
        elif address != POWER_ON_ADDRESS:
            raise ValueError(
                f"a VL53L0X held in standby boots at 0x{POWER_ON_ADDRESS:02X}, not 0x{address:02X}"
            )

    # -- the world ---------------------------------------------------------------------------
    @property
    def distance_mm(self) -> float | None:
        """What the sensor looks at, in mm; ``None`` when nothing is there."""
        return self._distance_mm

    @distance_mm.setter
    def distance_mm(self, value: float | None) -> None:
        if value is not None and value < 0:
            raise ValueError(f"a distance cannot be negative, got {value} mm")
        self._distance_mm = value

    @property
    def ranging_back_to_back(self) -> bool:
        """Whether the chip is ranging continuously (SYSRANGE_START bit 1 written, not
        stopped since)."""
        return self._continuous_since_s is not None

    def set_xshut(self, high: bool) -> None:
        """Drive the XSHUT pin: low = hardware standby and off the bus, high = boot at 0x29."""
        if high == self._xshut_high:
            return
        self._xshut_high = high
        if not high:
            self._detach()
            self._power_on_reset()
            return
        self._boot_done_s = self._clock.now() + TBOOT_MAX_S
        self._attach()

    @property
    def powered(self) -> bool:
        """Whether XSHUT is high (the chip is out of hardware standby)."""
        return self._xshut_high

    def peek(self, register: int, *, private_page: bool = False, page: int = 0) -> int:
        """A register's content as the chip holds it on ``page`` (the private page: 1).

        For tests; no side effects on the chip.
        """
        self._update()
        page = PRIVATE_PAGE if private_page else page
        if register == RESULT_INTERRUPT_STATUS and page == 0:
            return self._interrupt_status
        return self._bank(page)[register]

    # -- power and wiring ---------------------------------------------------------------------
    def _power_on_reset(self) -> None:
        self._registers = bytearray(256)
        for register, value in _POWER_ON_REGISTERS.items():
            self._registers[register] = value
        spads = GLOBAL_CONFIG_SPAD_ENABLES_REF_0
        self._registers[spads : spads + 6] = self._good_spad_map  # loaded from NVM at boot
        private = bytearray(256)
        for register, value in _POWER_ON_PRIVATE.items():
            private[register] = value
        self._pages = {0: self._registers, PRIVATE_PAGE: private}
        self._page = 0
        self._pointer = 0
        self._interrupt_status = 0
        self._busy_until_s: float | None = None
        self._continuous_since_s: float | None = None  # ranging back to back since then
        self._continuous_done = 0  # measurements completed since
        self._calibrating = False
        self._sampled_mm: float | None = None
        self.address = POWER_ON_ADDRESS
        self._boot_done_s = 0.0

    def _attach(self) -> None:
        self._bus.attach(self)
        self._attached = True

    def _detach(self) -> None:
        if self._attached and self._bus.device_at(self.address) is self:
            self._bus.detach(self.address)
        self._attached = False

    def _check_booted(self) -> None:
        if self._clock.now() < self._boot_done_s:
            raise bus_error(errno.EREMOTEIO, self.address)  # still booting: no ACK

    # -- ranging -------------------------------------------------------------------------------
    def _start(self) -> None:
        self._calibrating = self._registers[SYSTEM_SEQUENCE_CONFIG] in CALIBRATION_SEQUENCES
        duration = CALIBRATION_TIME_S if self._calibrating else self.timing_budget_s
        self._busy_until_s = self._clock.now() + duration
        self._sampled_mm = self._distance_mm

    def _update(self) -> None:
        if self._continuous_since_s is not None:
            done = int((self._clock.now() - self._continuous_since_s) / self.timing_budget_s)
            if done > self._continuous_done:
                self.measurements += done - self._continuous_done - 1
                self._continuous_done = done
                self._interrupt_status = INTERRUPT_NEW_SAMPLE_READY
                self._sampled_mm = self._distance_mm
                self._result()
            return
        if self._busy_until_s is None or self._clock.now() < self._busy_until_s:
            return
        self._busy_until_s = None
        self._interrupt_status = INTERRUPT_NEW_SAMPLE_READY
        if not self._calibrating:
            self._result()

    def _result(self) -> None:
        """A measurement of the distance sampled completes: its result registers."""
        self.measurements += 1
        distance = self._sampled_mm
        if distance is None or distance > self.max_range_mm:
            status, range_mm = DEVICE_RANGE_STATUS_MSRC_NO_TARGET, RANGE_OUT_OF_RANGE_MM
        else:
            status, range_mm = (
                DEVICE_RANGE_STATUS_VALID,
                min(round(distance), RANGE_OUT_OF_RANGE_MM - 1),
            )
        self._registers[RESULT_RANGE_STATUS] = status << DEVICE_RANGE_STATUS_SHIFT
        self._registers[RESULT_RANGE_MM] = range_mm >> 8
        self._registers[RESULT_RANGE_MM + 1] = range_mm & 0xFF

    # -- the wire ------------------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        self._check_booted()
        self._update()
        if not data:
            return
        self._pointer = data[0]
        for value in data[1:]:
            self._write_register(self._pointer, value)
            self._pointer = (self._pointer + 1) & 0xFF

    def _bank(self, page: int) -> bytearray:
        """The registers of ``page`` (a page never written reads 0)."""
        return self._pages.setdefault(page, bytearray(256))

    def _write_register(self, register: int, value: int) -> None:
        if register == PAGE_SELECT:
            self._page = value
            return
        if self._page:
            self._write_paged(register, value)
            return
        if register in _READ_ONLY:
            return
        if register == SYSRANGE_START:
            self._update()  # a measurement already complete is kept
            self._continuous_since_s = None
            if value & SYSRANGE_START_BACK_TO_BACK:
                self._continuous_since_s, self._continuous_done = self._clock.now(), 0
                self._busy_until_s = None  # a single shot under way gives way
            elif value & SYSRANGE_START_SINGLESHOT:
                self._start()
            self._registers[register] = value & ~0x01  # the start bit clears once begun
        elif register == SYSTEM_INTERRUPT_CLEAR:
            if value & 0x01:
                self._interrupt_status = 0
            self._registers[register] = value
        elif register == I2C_SLAVE_DEVICE_ADDRESS:
            self._move_to(value & 0x7F)
        else:
            self._registers[register] = value

    def _write_paged(self, register: int, value: int) -> None:
        bank = self._bank(self._page)
        bank[register] = value
        if self._page == NVM_PAGE and register == NVM_CONTROL and value == 0x00:
            self._strobe_nvm(bank)

    def _strobe_nvm(self, bank: bytearray) -> None:
        """The NVM read strobe: the word at NVM_ADDRESS into NVM_DATA, if NVM is on."""
        enabled = self._bank(NVM_ENABLE_PAGE)[NVM_CONTROL] & NVM_ENABLE
        if not enabled or not bank[NVM_POWER] & 0x01:
            return  # the strobe never completes: NVM_CONTROL keeps reading 0
        word = self._nvm.get(bank[NVM_ADDRESS], 0)
        bank[NVM_DATA : NVM_DATA + 4] = word.to_bytes(4, "big")
        bank[NVM_CONTROL] = NVM_READ_DONE

    def _move_to(self, new_address: int) -> None:
        if not 0x03 <= new_address <= 0x77:
            raise ValueError(f"simulated VL53L0X: 0x{new_address:02X} is not a usable address")
        if new_address == self.address:
            return
        holder = self._bus.device_at(new_address)
        if holder is not None:
            raise ValueError(
                f"simulated VL53L0X moving to 0x{new_address:02X}, already used by "
                f"{type(holder).__name__}: two chips would answer there"
            )
        self._bus.readdress(self.address, new_address)
        self._registers[I2C_SLAVE_DEVICE_ADDRESS] = new_address

    def read(self, length: int) -> bytes:
        self._check_booted()
        self._update()
        out = bytearray()
        for _ in range(length):
            if self._pointer == PAGE_SELECT:
                out.append(self._page)
            elif self._page:
                out.append(self._bank(self._page)[self._pointer])
            elif self._pointer == RESULT_INTERRUPT_STATUS:
                out.append(self._interrupt_status)
            else:
                out.append(self._registers[self._pointer])
            self._pointer = (self._pointer + 1) & 0xFF
        return bytes(out)
