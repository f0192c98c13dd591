"""ST VL53L0X time-of-flight distance sensor (I2C, default address 0x29).

The vest carries three of them (left, centre, right). All three boot at 0x29, so each must
be moved to its own address before the next one is switched on:
:class:`~engine.hardware.xshut.XshutChain` does that with their XSHUT lines and
:meth:`VL53L0X.set_address`; a TCA9548A multiplexer (:mod:`engine.drivers.tca9548a`)
is the other way, each sensor keeping 0x29 on its own channel.

The initialisation follows the order of ST's API as Pololu's library distils it, keeping
the steps that matter for single-shot ranging:

* I/O in 2V8 mode (bit 0 of VHV_CONFIG_PAD_SCL_SDA__EXTSUP_HV) and I2C standard mode;
* read the "stop variable" from the private register page (it is written back before each
  single-shot measurement, as ST's code does);
* disable the MSRC and pre-range signal-rate limit checks and set the final-range signal
  rate limit (0.25 MCPS, Q9.7 fixed point);
* interrupt on "new sample ready", active low, cleared;
* sequence steps DSS, pre-range and final range (0xE8), then the VHV and phase
  reference calibrations.

Simplified, compared with ST's full sequence: the reference-SPAD selection (read from the
chip's NVM and written to GLOBAL_CONFIG_SPAD_ENABLES_REF_*), the ~80-register default
tuning table and the timing-budget recomputation are not done. The chip then ranges with
its power-on SPAD map and tuning and its default ~33 ms timing budget; readings are
usable for presence and tracking at arm's length but can be less accurate or shorter-ranged
than with the full ST sequence. Port those steps if millimetre accuracy ever matters.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from engine.clock import Clock
from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, device_error, i2c_place
from engine.errors import DeviceError

CHIP = "VL53L0X"
DEFAULT_ADDRESS = 0x29

# -- register map (ST API names) ------------------------------------------------------------
SYSRANGE_START = 0x00
SYSRANGE_START_SINGLESHOT = 0x01  # bit 0: start; clears itself once ranging has begun
SYSTEM_SEQUENCE_CONFIG = 0x01
SYSTEM_INTERRUPT_CONFIG_GPIO = 0x0A
INTERRUPT_NEW_SAMPLE_READY = 0x04
SYSTEM_INTERRUPT_CLEAR = 0x0B
RESULT_INTERRUPT_STATUS = 0x13
RESULT_INTERRUPT_MASK = 0x07
RESULT_RANGE_STATUS = 0x14
RESULT_RANGE_MM_OFFSET = 10  # range in mm, big-endian 16-bit, at RESULT_RANGE_STATUS + 10
RESULT_BLOCK_LENGTH = 12
FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT = 0x44  # 16-bit, Q9.7 MCPS
MSRC_CONFIG_CONTROL = 0x60
MSRC_DISABLE_SIGNAL_RATE_CHECKS = 0x12  # bit 1 MSRC, bit 4 pre-range
GPIO_HV_MUX_ACTIVE_HIGH = 0x84
GPIO_HV_MUX_POLARITY_HIGH = 0x10
I2C_STANDARD_MODE = 0x88
VHV_CONFIG_PAD_SCL_SDA_EXTSUP_HV = 0x89
VHV_CONFIG_2V8 = 0x01
I2C_SLAVE_DEVICE_ADDRESS = 0x8A
IDENTIFICATION_MODEL_ID = 0xC0
IDENTITY = (0xEE, 0xAA, 0x10)  # registers 0xC0, 0xC1, 0xC2 (model, ?, revision)

# The private page that holds the stop variable (register 0x91 with 0xFF = 0x01).
POWER_MANAGEMENT = 0x80
PAGE_SELECT = 0xFF
STOP_VARIABLE = 0x91

SEQUENCE_ALL = 0xFF
SEQUENCE_DSS_PRE_FINAL = 0xE8  # DSS, pre-range and final range; no TCC, no MSRC
SEQUENCE_VHV_CALIBRATION = 0x01
SEQUENCE_PHASE_CALIBRATION = 0x02
VHV_CALIBRATION_START = 0x40

# Bits 6:3 of RESULT_RANGE_STATUS: the device's range status; 11 means a valid range.
DEVICE_RANGE_STATUS_VALID = 11
DEVICE_RANGE_STATUS_TOO_CLOSE = frozenset({8, 10})
"""Device range statuses of a target closer than the chip can range ("min range fail")."""
RANGE_OUT_OF_RANGE_MM = 8190  # the chip reports 8190 or 8191 when nothing is in range
RANGE_CODE_MAX = 8191  # the range field never holds more
MAX_RANGE_MM = 2000  # the chip's reach (long-range mode); a valid range beyond it is garbled

BOOT_TIME_S = 0.002  # after XSHUT rises; the datasheet's tBOOT is 1.2 ms max
POLL_INTERVAL_S = 0.002


# -- pure conversions -------------------------------------------------------------------------
def signal_rate_limit_to_register(limit_mcps: float) -> int:
    """A signal rate limit in mega counts per second as the chip's Q9.7 fixed-point value."""
    if not 0.0 <= limit_mcps < 512.0:
        raise ValueError(f"VL53L0X signal rate limit must be 0..511.99 MCPS, got {limit_mcps}")
    return round(limit_mcps * (1 << 7))


def device_range_status(status_byte: int) -> int:
    """The device range status (bits 6:3) of RESULT_RANGE_STATUS; 11 is a valid range."""
    return (status_byte >> 3) & 0x0F


def decode_range(status_byte: int, range_mm: int) -> int | None:
    """The distance in mm, or ``None`` when the chip found nothing valid in range. A
    target too close to range (the device's "min range" statuses, 8 and 10: a hand over
    the sensor) is 0 mm: something is right there, the worst case for whoever relies on
    it."""
    status = device_range_status(status_byte)
    if status in DEVICE_RANGE_STATUS_TOO_CLOSE:
        return 0
    if range_mm >= RANGE_OUT_OF_RANGE_MM:
        return None
    if status != DEVICE_RANGE_STATUS_VALID:
        return None
    return range_mm


def check_address(address: int) -> int:
    """A usable 7-bit address for a VL53L0X (0x08..0x77), or ValueError."""
    if not 0x08 <= address <= 0x77:
        raise ValueError(f"{CHIP} I2C address must be 0x08..0x77, got 0x{address:02X}")
    return address


class VL53L0X:
    """One VL53L0X, checked and initialised on construction; single-shot ranging.

    ``timeout_s`` bounds one measurement (start to result, on ``clock``); a chip that does
    not finish in time raises :class:`DeviceError`. Thread-safe: one measurement at a time.
    """

    def __init__(
        self,
        bus: I2CBus,
        *,
        address: int = DEFAULT_ADDRESS,
        clock: Clock,
        timeout_s: float = 0.1,
        signal_rate_limit_mcps: float = 0.25,
        io_2v8: bool = True,
    ) -> None:
        if timeout_s <= 0:
            raise ValueError(f"{CHIP} timeout_s must be positive, got {timeout_s}")
        self._bus = bus
        self._address = check_address(address)
        self._clock = clock
        self.timeout_s = timeout_s
        self._lock = threading.Lock()
        self._check_identity()
        self._stop_variable = 0
        self._init(signal_rate_limit_to_register(signal_rate_limit_mcps), io_2v8)

    @property
    def address(self) -> int:
        """The 7-bit I2C address the chip answers on now."""
        return self._address

    def __repr__(self) -> str:
        return f"VL53L0X(address=0x{self._address:02X})"

    # -- bus helpers ------------------------------------------------------------------------
    def _read(self, register: int) -> int:
        return self._bus.read_byte_data(self._address, register)

    def _write(self, register: int, value: int) -> None:
        self._bus.write_byte_data(self._address, register, value & 0xFF)

    def _write_u16(self, register: int, value: int) -> None:
        # 16-bit registers are big-endian: most significant byte at the lower address.
        self._bus.write_i2c_block_data(self._address, register, [value >> 8, value & 0xFF])

    def _where(self) -> str:
        return f"{CHIP} at 0x{self._address:02X}"

    def _check_identity(self) -> None:
        try:
            identity = tuple(
                self._bus.read_i2c_block_data(self._address, IDENTIFICATION_MODEL_ID, 3)
            )
        except OSError as err:
            raise device_error(
                f"{self._where()} did not answer: {err.strerror or err}", err
            ) from err
        if identity != IDENTITY:
            found = " ".join(f"0x{b:02X}" for b in identity)
            raise DeviceError(
                f"{self._where()}: identity registers 0xC0..0xC2 read {found}, "
                f"expected 0xEE 0xAA 0x10: not a VL53L0X"
            )

    # -- initialisation --------------------------------------------------------------------
    def _init(self, signal_rate_limit: int, io_2v8: bool) -> None:
        if io_2v8:
            pad = self._read(VHV_CONFIG_PAD_SCL_SDA_EXTSUP_HV)
            self._write(VHV_CONFIG_PAD_SCL_SDA_EXTSUP_HV, pad | VHV_CONFIG_2V8)
        self._write(I2C_STANDARD_MODE, 0x00)
        self._stop_variable = self._read_stop_variable()
        msrc = self._read(MSRC_CONFIG_CONTROL)
        self._write(MSRC_CONFIG_CONTROL, msrc | MSRC_DISABLE_SIGNAL_RATE_CHECKS)
        self._write_u16(FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT, signal_rate_limit)
        self._write(SYSTEM_SEQUENCE_CONFIG, SEQUENCE_ALL)
        # (reference SPADs and the default tuning table would go here: see module docstring)
        self._write(SYSTEM_INTERRUPT_CONFIG_GPIO, INTERRUPT_NEW_SAMPLE_READY)
        mux = self._read(GPIO_HV_MUX_ACTIVE_HIGH)
        self._write(GPIO_HV_MUX_ACTIVE_HIGH, mux & ~GPIO_HV_MUX_POLARITY_HIGH)
        self._write(SYSTEM_INTERRUPT_CLEAR, 0x01)
        self._write(SYSTEM_SEQUENCE_CONFIG, SEQUENCE_DSS_PRE_FINAL)
        self._write(SYSTEM_SEQUENCE_CONFIG, SEQUENCE_VHV_CALIBRATION)
        self._single_reference_calibration(VHV_CALIBRATION_START, "VHV calibration")
        self._write(SYSTEM_SEQUENCE_CONFIG, SEQUENCE_PHASE_CALIBRATION)
        self._single_reference_calibration(0x00, "phase calibration")
        self._write(SYSTEM_SEQUENCE_CONFIG, SEQUENCE_DSS_PRE_FINAL)

    def _enter_private_page(self) -> None:
        self._write(POWER_MANAGEMENT, 0x01)
        self._write(PAGE_SELECT, 0x01)
        self._write(0x00, 0x00)

    def _leave_private_page(self) -> None:
        self._write(0x00, 0x01)
        self._write(PAGE_SELECT, 0x00)
        self._write(POWER_MANAGEMENT, 0x00)

    def _read_stop_variable(self) -> int:
        self._enter_private_page()
        value = self._read(STOP_VARIABLE)
        self._leave_private_page()
        return value

    def _single_reference_calibration(self, start_bits: int, what: str) -> None:
        self._write(SYSRANGE_START, SYSRANGE_START_SINGLESHOT | start_bits)
        deadline = self._clock.now() + self.timeout_s
        self._wait_for(self._interrupt_raised, deadline, what)
        self._write(SYSTEM_INTERRUPT_CLEAR, 0x01)
        self._write(SYSRANGE_START, 0x00)

    # -- ranging ---------------------------------------------------------------------------
    def _interrupt_raised(self) -> bool:
        return self._read(RESULT_INTERRUPT_STATUS) & RESULT_INTERRUPT_MASK != 0

    def _start_bit_clear(self) -> bool:
        return self._read(SYSRANGE_START) & SYSRANGE_START_SINGLESHOT == 0

    def _wait_for(self, condition: Callable[[], bool], deadline_s: float, what: str) -> None:
        """Poll ``condition`` through the clock until true; DeviceError after the deadline."""
        while not condition():
            if self._clock.now() >= deadline_s:
                raise DeviceError(
                    f"{self._where()}: {what} did not finish within {self.timeout_s} s"
                )
            self._clock.sleep(POLL_INTERVAL_S)

    def read_range_mm(self) -> int | None:
        """One single-shot measurement: the distance in mm, or ``None`` if out of range.

        Takes the chip's timing budget (~33 ms) on the clock. Raises :class:`DeviceError`
        when the chip does not finish within ``timeout_s``, ``OSError`` on bus errors, and
        :class:`~engine.drivers.device_errors.ImplausibleReadingError` for a valid range
        beyond the chip's ~2 m, or a range field above 8191.
        """
        with self._lock:
            self._enter_private_page()
            self._write(STOP_VARIABLE, self._stop_variable)
            self._leave_private_page()
            self._write(SYSTEM_INTERRUPT_CLEAR, 0x01)  # a stale result must not pass for ours
            self._write(SYSRANGE_START, SYSRANGE_START_SINGLESHOT)
            deadline = self._clock.now() + self.timeout_s
            self._wait_for(self._start_bit_clear, deadline, "start of ranging")
            self._wait_for(self._interrupt_raised, deadline, "ranging")
            result = self._bus.read_i2c_block_data(
                self._address, RESULT_RANGE_STATUS, RESULT_BLOCK_LENGTH
            )
            self._write(SYSTEM_INTERRUPT_CLEAR, 0x01)
        offset = RESULT_RANGE_MM_OFFSET
        range_mm = (result[offset] << 8) | result[offset + 1]
        distance_mm = decode_range(result[0], range_mm)
        if range_mm > RANGE_CODE_MAX or (distance_mm is not None and distance_mm > MAX_RANGE_MM):
            valid = device_range_status(result[0]) == DEVICE_RANGE_STATUS_VALID
            raise ImplausibleReadingError(
                chip=CHIP,
                place=i2c_place(self._address),
                what="range with a valid status" if valid else "range",
                value=f"{range_mm} mm",
                plausible=f"0..{MAX_RANGE_MM} mm, or {RANGE_OUT_OF_RANGE_MM}..{RANGE_CODE_MAX} "
                "for nothing in range",
            )
        return distance_mm

    def set_address(self, new_address: int) -> None:
        """Move the chip to ``new_address`` (kept until power-off or XSHUT low)."""
        check_address(new_address)
        with self._lock:
            self._write(I2C_SLAVE_DEVICE_ADDRESS, new_address & 0x7F)
            old, self._address = self._address, new_address
            try:
                self._read(IDENTIFICATION_MODEL_ID)
            except OSError as err:
                raise device_error(
                    f"{CHIP} moved from 0x{old:02X} but does not answer at "
                    f"0x{new_address:02X}: {err.strerror or err}",
                    err,
                ) from err
