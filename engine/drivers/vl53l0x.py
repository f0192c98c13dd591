"""ST VL53L0X time-of-flight distance sensor (I2C, default address 0x29).

The vest carries three of them (left, centre, right). All three boot at 0x29, so each must
be moved to its own address before the next one is switched on:
:class:`~engine.hardware.xshut.XshutChain` does that with their XSHUT lines and
:meth:`VL53L0X.set_address`; a TCA9548A multiplexer (:mod:`engine.drivers.tca9548a`)
is the other way, each sensor keeping 0x29 on its own channel.

The bring-up is ST's (``VL53L0X_DataInit``, ``StaticInit`` and ``PerformRefCalibration``
of its API), in the order Pololu's library distils it:

* I/O in 2V8 mode (bit 0 of VHV_CONFIG_PAD_SCL_SDA__EXTSUP_HV) and I2C standard mode;
* read the "stop variable" from the private register page (it is written back before each
  single-shot measurement, as ST's code does);
* disable the MSRC and pre-range signal-rate limit checks and set the final-range signal
  rate limit (0.25 MCPS by default, Q9.7 fixed point); the tuning table below writes both
  registers again, as in ST's API, and a limit other than its 0.25 MCPS is set once more;
* the reference SPADs: their count, kind and map of working SPADs read from the chip's
  NVM through ST's handshake (:mod:`engine.drivers.vl53l0x_spads`), then enabled;
* ST's default tuning table (:mod:`engine.drivers.vl53l0x_tuning`);
* interrupt on "new sample ready", active low, cleared;
* the timing budget read back with the tuning's sequence steps and applied again to the
  sequence DSS, pre-range and final range (0xE8), so the final range gets the time TCC and
  MSRC no longer take (:mod:`engine.drivers.vl53l0x_timing`);
* the VHV and phase reference calibrations.

``tests/drivers/test_vl53l0x_bring_up.py`` holds these register writes against those of
Adafruit's CircuitPython driver on the simulated chip. Not done: ST's reference SPAD
management (a calibration on a target, for a chip whose NVM is invalid: such a chip is
refused), offset and cross-talk calibration, and timed continuous ranging (back-to-back
continuous ranging is: :meth:`VL53L0X.start_continuous`).
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterable, Iterator

from engine.clock import Clock
from engine.drivers import vl53l0x_registers as reg
from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import device_error, i2c_place
from engine.drivers.forwarding_bus import write_each
from engine.drivers.vl53l0x_results import CHIP, distance_in
from engine.drivers.vl53l0x_spads import (
    SPAD_MAP_BYTES,
    ReferenceSpads,
    from_nvm_words,
    select_reference_spads,
)
from engine.drivers.vl53l0x_timing import (
    TimingRegisters,
    final_range_timeout_for,
    implausible,
    timing_budget_us,
)
from engine.drivers.vl53l0x_tuning import DEFAULT_TUNING, TUNING_SIGNAL_RATE_LIMIT
from engine.errors import DeviceError

DEFAULT_ADDRESS = reg.POWER_ON_ADDRESS
# What the chip kind probes with (engine.hardware.chips.vl53l0x):
IDENTIFICATION_MODEL_ID = reg.IDENTIFICATION_MODEL_ID  # the first identity register
IDENTITY = reg.IDENTITY  # 0xC0..0xC2

BOOT_TIME_S = 0.002  # after XSHUT rises, with a margin over tBOOT (reg.TBOOT_MAX_S)
POLL_INTERVAL_S = 0.002
FIRST_LOOK = 1.0
"""A measurement is first asked about after this share of the timing budget: it takes the
budget (ST: the budget is the time of one measurement), so asking every 2 ms from the start
was 15 bus reads of nothing per reading, on the bus the touch and force chips share (issue
24, an idle robot); a chip that finishes sooner is read at most that much later."""


# -- pure conversions -------------------------------------------------------------------------
def signal_rate_limit_to_register(limit_mcps: float) -> int:
    """A signal rate limit in mega counts per second as the chip's Q9.7 fixed-point value."""
    if not 0.0 <= limit_mcps < 512.0:
        raise ValueError(f"VL53L0X signal rate limit must be 0..511.99 MCPS, got {limit_mcps}")
    return round(limit_mcps * (1 << 7))


def check_address(address: int) -> int:
    """A usable 7-bit address for a VL53L0X (0x08..0x77), or ValueError."""
    if not 0x08 <= address <= 0x77:
        raise ValueError(f"{CHIP} I2C address must be 0x08..0x77, got 0x{address:02X}")
    return address


class VL53L0X:
    """One VL53L0X, checked and brought up as ST does on construction; single-shot ranging,
    or back to back (:meth:`start_continuous`).

    ``timeout_s`` bounds one measurement (start to result, on ``clock``), and each wait of
    the bring-up; a chip that does not finish in time raises :class:`DeviceError`, as does
    one whose NVM holds unusable reference SPAD data. Thread-safe: one measurement at a time.
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
        self._timing_budget_us = 0
        self._continuous = False
        self._init(signal_rate_limit_to_register(signal_rate_limit_mcps), io_2v8)

    @property
    def address(self) -> int:
        """The 7-bit I2C address the chip answers on now."""
        return self._address

    @property
    def timing_budget_s(self) -> float:
        """How long one measurement takes by the chip's timing registers, in seconds."""
        return self._timing_budget_us / 1e6

    def __repr__(self) -> str:
        return f"VL53L0X(address=0x{self._address:02X})"

    # -- bus helpers ------------------------------------------------------------------------
    def _read(self, register: int) -> int:
        return self._bus.read_byte_data(self._address, register)

    def _write(self, register: int, value: int) -> None:
        self._bus.write_byte_data(self._address, register, value & 0xFF)

    def _write_all(self, writes: Iterable[tuple[int, int]]) -> None:
        """The writes in order, as one access of a wrapping bus (one bus-manager job)."""
        write_each(self._bus, self._address, [(r, v & 0xFF) for r, v in writes])

    def _write_u16(self, register: int, value: int) -> None:
        # 16-bit registers are big-endian: most significant byte at the lower address.
        self._bus.write_i2c_block_data(self._address, register, [value >> 8, value & 0xFF])

    def _read_block(self, register: int, length: int) -> bytes:
        return bytes(self._bus.read_i2c_block_data(self._address, register, length))

    def _read_u16(self, register: int) -> int:
        return int.from_bytes(self._read_block(register, 2), "big")

    def _where(self) -> str:
        return f"{CHIP} at 0x{self._address:02X}"

    def _check_identity(self) -> None:
        try:
            identity = tuple(
                self._bus.read_i2c_block_data(self._address, reg.IDENTIFICATION_MODEL_ID, 3)
            )
        except OSError as err:
            raise device_error(
                f"{self._where()} did not answer: {err.strerror or err}", err
            ) from err
        if identity != reg.IDENTITY:
            found = " ".join(f"0x{b:02X}" for b in identity)
            raise DeviceError(
                f"{self._where()}: identity registers 0xC0..0xC2 read {found}, "
                f"expected 0xEE 0xAA 0x10: not a VL53L0X"
            )

    # -- initialisation --------------------------------------------------------------------
    def _init(self, signal_rate_limit: int, io_2v8: bool) -> None:
        if io_2v8:
            pad = self._read(reg.VHV_CONFIG_PAD_SCL_SDA_EXTSUP_HV)
            self._write(reg.VHV_CONFIG_PAD_SCL_SDA_EXTSUP_HV, pad | reg.VHV_CONFIG_2V8)
        self._write(reg.I2C_STANDARD_MODE, 0x00)
        self._stop_variable = self._read_stop_variable()
        msrc = self._read(reg.MSRC_CONFIG_CONTROL)
        self._write(reg.MSRC_CONFIG_CONTROL, msrc | reg.MSRC_DISABLE_SIGNAL_RATE_CHECKS)
        self._write_u16(reg.FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT, signal_rate_limit)
        self._write(reg.SYSTEM_SEQUENCE_CONFIG, reg.SEQUENCE_ALL)
        self._set_reference_spads(self._read_reference_spads())
        with self._off_main_page():
            self._write_all(DEFAULT_TUNING)
        if signal_rate_limit != TUNING_SIGNAL_RATE_LIMIT:  # the table set its own
            self._write_u16(reg.FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT, signal_rate_limit)
        self._write(reg.SYSTEM_INTERRUPT_CONFIG_GPIO, reg.INTERRUPT_NEW_SAMPLE_READY)
        mux = self._read(reg.GPIO_HV_MUX_ACTIVE_HIGH)
        self._write(reg.GPIO_HV_MUX_ACTIVE_HIGH, mux & ~reg.GPIO_HV_MUX_POLARITY_HIGH)
        self._write(reg.SYSTEM_INTERRUPT_CLEAR, 0x01)
        budget_us = timing_budget_us(self._timing_registers())  # with the tuning's steps
        self._write(reg.SYSTEM_SEQUENCE_CONFIG, reg.SEQUENCE_DSS_PRE_FINAL)
        self._set_timing_budget_us(budget_us)
        self._write(reg.SYSTEM_SEQUENCE_CONFIG, reg.SEQUENCE_VHV_CALIBRATION)
        self._single_reference_calibration(reg.VHV_CALIBRATION_START, "VHV calibration")
        self._write(reg.SYSTEM_SEQUENCE_CONFIG, reg.SEQUENCE_PHASE_CALIBRATION)
        self._single_reference_calibration(0x00, "phase calibration")
        self._write(reg.SYSTEM_SEQUENCE_CONFIG, reg.SEQUENCE_DSS_PRE_FINAL)

    @contextlib.contextmanager
    def _off_main_page(self) -> Iterator[None]:
        """Writes that select another register page; after a failure among them, a try to
        select page 0 again, so that a retry finds the identity registers where they are."""
        try:
            yield
        except Exception:
            with contextlib.suppress(OSError):
                self._write_all(((reg.PAGE_SELECT, 0x01), *reg.LEAVE_PRIVATE_PAGE))
            raise

    def _read_stop_variable(self) -> int:
        with self._off_main_page():
            self._write_all(reg.ENTER_PRIVATE_PAGE)
            value = self._read(reg.STOP_VARIABLE)
            self._write_all(reg.LEAVE_PRIVATE_PAGE)
        return value

    def _read_reference_spads(self) -> ReferenceSpads:
        """The reference SPAD data from NVM (ST's ``VL53L0X_get_info_from_device``)."""
        with self._off_main_page():
            self._write_all((*reg.ENTER_PRIVATE_PAGE, (reg.PAGE_SELECT, reg.NVM_ENABLE_PAGE)))
            self._write(reg.NVM_CONTROL, self._read(reg.NVM_CONTROL) | reg.NVM_ENABLE)
            self._write_all(
                (
                    (reg.PAGE_SELECT, reg.NVM_PAGE),
                    (reg.NVM_POWER, 0x01),
                    (reg.POWER_MANAGEMENT, 0x01),
                )
            )
            words = [
                self._read_nvm_word(word) for word in (reg.NVM_SPAD_INFO, *reg.NVM_GOOD_SPAD_MAP)
            ]
            self._write_all(((reg.NVM_POWER, 0x00), (reg.PAGE_SELECT, reg.NVM_ENABLE_PAGE)))
            self._write(reg.NVM_CONTROL, self._read(reg.NVM_CONTROL) & ~reg.NVM_ENABLE)
            self._write_all(((reg.PAGE_SELECT, 0x01), *reg.LEAVE_PRIVATE_PAGE))
        return from_nvm_words(*words)

    def _read_nvm_word(self, word: int) -> int:
        """One 32-bit NVM word: its address, the read strobe, the wait, the data."""
        self._write(reg.NVM_ADDRESS, word)
        self._write(reg.NVM_CONTROL, 0x00)
        deadline = self._clock.now() + self.timeout_s
        self._wait_for(lambda: self._read(reg.NVM_CONTROL) != 0, deadline, f"NVM read 0x{word:02X}")
        self._write(reg.NVM_CONTROL, 0x01)
        return int.from_bytes(self._read_block(reg.NVM_DATA, 4), "big")

    def _set_reference_spads(self, spads: ReferenceSpads) -> None:
        """Enable the reference SPADs the NVM names (ST's ``VL53L0X_set_reference_spads``)."""
        try:
            enables = select_reference_spads(spads)
        except ValueError as err:
            raise DeviceError(f"{self._where()}: {err}") from err
        with self._off_main_page():
            self._write_all(
                (
                    (reg.PAGE_SELECT, 0x01),
                    (reg.DYNAMIC_SPAD_REF_EN_START_OFFSET, 0x00),
                    (reg.DYNAMIC_SPAD_NUM_REQUESTED_REF_SPAD, reg.DYNAMIC_SPADS_REQUESTED),
                    (reg.PAGE_SELECT, 0x00),
                )
            )
        self._write(reg.GLOBAL_CONFIG_REF_EN_START_SELECT, reg.REF_EN_START_SELECT)
        self._bus.write_i2c_block_data(
            self._address, reg.GLOBAL_CONFIG_SPAD_ENABLES_REF_0, [*enables]
        )
        held = self._read_block(reg.GLOBAL_CONFIG_SPAD_ENABLES_REF_0, SPAD_MAP_BYTES)
        if held != enables:
            raise DeviceError(
                f"{self._where()}: reference SPAD enables read back {held.hex(' ')}, "
                f"written {enables.hex(' ')}"
            )

    def _timing_registers(self) -> TimingRegisters:
        """The registers the timing budget depends on; DeviceError naming the register when
        one reads what no working chip holds (a garbled read never becomes a budget)."""
        timing = TimingRegisters(
            sequence_config=self._read(reg.SYSTEM_SEQUENCE_CONFIG),
            pre_range_vcsel_period=self._read(reg.PRE_RANGE_CONFIG_VCSEL_PERIOD),
            msrc_timeout=self._read(reg.MSRC_CONFIG_TIMEOUT_MACROP),
            pre_range_timeout=self._read_u16(reg.PRE_RANGE_CONFIG_TIMEOUT_MACROP_HI),
            final_range_vcsel_period=self._read(reg.FINAL_RANGE_CONFIG_VCSEL_PERIOD),
            final_range_timeout=self._read_u16(reg.FINAL_RANGE_CONFIG_TIMEOUT_MACROP_HI),
        )
        why = implausible(timing)
        if why is not None:
            raise DeviceError(f"{self._where()}: {why}, which no working VL53L0X holds")
        return timing

    def _set_timing_budget_us(self, budget_us: int) -> None:
        """Give the final range what the budget leaves (ST's ``set_measurement_timing_
        budget_micro_seconds``); DeviceError when the registers leave it nothing."""
        try:
            encoded = final_range_timeout_for(self._timing_registers(), budget_us)
        except ValueError as err:
            raise DeviceError(f"{self._where()}: {err}") from err
        self._write_u16(reg.FINAL_RANGE_CONFIG_TIMEOUT_MACROP_HI, encoded)
        self._timing_budget_us = budget_us

    def _single_reference_calibration(self, start_bits: int, what: str) -> None:
        self._write(reg.SYSRANGE_START, reg.SYSRANGE_START_SINGLESHOT | start_bits)
        deadline = self._clock.now() + self.timeout_s
        self._wait_for(self._interrupt_raised, deadline, what)
        self._write(reg.SYSTEM_INTERRUPT_CLEAR, 0x01)
        self._write(reg.SYSRANGE_START, 0x00)

    # -- ranging ---------------------------------------------------------------------------
    def _interrupt_raised(self) -> bool:
        return self._read(reg.RESULT_INTERRUPT_STATUS) & reg.RESULT_INTERRUPT_MASK != 0

    def _start_bit_clear(self) -> bool:
        return self._read(reg.SYSRANGE_START) & reg.SYSRANGE_START_SINGLESHOT == 0

    def _wait_for(self, condition: Callable[[], bool], deadline_s: float, what: str) -> None:
        """Poll ``condition`` through the clock until true; DeviceError after the deadline."""
        while not condition():
            if self._clock.now() >= deadline_s:
                raise DeviceError(
                    f"{self._where()}: {what} did not finish within {self.timeout_s} s"
                )
            self._clock.sleep(POLL_INTERVAL_S)

    def read_range_mm(self) -> int | None:
        """The distance in mm, or ``None`` if nothing is in range: one single-shot
        measurement, or, ranging continuously (:meth:`start_continuous`), the latest.

        A single shot takes the chip's timing budget (~33 ms) on the clock; ranging
        continuously, a measurement is ready at once unless none came since the last read
        (then it waits for the next). Raises :class:`DeviceError` when the chip does not
        finish within ``timeout_s``, ``OSError`` on bus errors, and
        :class:`~engine.drivers.device_errors.ImplausibleReadingError` for a valid range
        beyond the chip's ~2 m, or a range field above 8191.
        """
        with self._lock:
            if self._continuous:
                result = self._next_continuous_result()
            else:
                result = self._single_shot_result()
        return distance_in(result, i2c_place(self._address))

    def _start_ranging(self, mode: int) -> None:
        with self._off_main_page():
            self._write_all(
                (
                    *reg.ENTER_PRIVATE_PAGE,
                    (reg.STOP_VARIABLE, self._stop_variable),
                    *reg.LEAVE_PRIVATE_PAGE,
                    # a stale result must not pass for ours
                    (reg.SYSTEM_INTERRUPT_CLEAR, 0x01),
                    (reg.SYSRANGE_START, mode),
                )
            )

    def _single_shot_result(self) -> bytes:
        self._start_ranging(reg.SYSRANGE_START_SINGLESHOT)
        started = self._clock.now()
        deadline = started + self.timeout_s
        self._wait_for(self._start_bit_clear, deadline, "start of ranging")
        self._clock.sleep_until(started + FIRST_LOOK * self.timing_budget_s)
        self._wait_for(self._interrupt_raised, deadline, "ranging")
        result = self._read_block(reg.RESULT_RANGE_STATUS, reg.RESULT_BLOCK_LENGTH)
        self._write(reg.SYSTEM_INTERRUPT_CLEAR, 0x01)
        return result

    def _next_continuous_result(self) -> bytes:
        """The interrupt status and the result in one read; when no measurement came
        since the last, asked again every ``POLL_INTERVAL_S`` until one does."""
        deadline = self._clock.now() + self.timeout_s
        while True:
            block = self._read_block(reg.RESULT_INTERRUPT_STATUS, 1 + reg.RESULT_BLOCK_LENGTH)
            if block[0] & reg.RESULT_INTERRUPT_MASK:
                break
            if self._clock.now() >= deadline:
                raise DeviceError(
                    f"{self._where()}: ranging continuously, no measurement came within "
                    f"{self.timeout_s} s"
                )
            self._clock.sleep(POLL_INTERVAL_S)
        self._write(reg.SYSTEM_INTERRUPT_CLEAR, 0x01)
        return block[1:]

    def start_continuous(self) -> None:
        """Range back to back, a measurement every timing budget, until
        :meth:`stop_continuous` (as Adafruit's and Pololu's drivers do): a read then takes
        two bus transfers and no wait, where a single shot takes six and the budget."""
        with self._lock:
            self._start_ranging(reg.SYSRANGE_START_BACK_TO_BACK)
            self._continuous = True

    def stop_continuous(self) -> None:
        """Back to single-shot ranging."""
        with self._lock, self._off_main_page():
            self._write_all(
                (
                    (reg.SYSRANGE_START, 0x00),
                    *reg.ENTER_PRIVATE_PAGE,
                    (reg.STOP_VARIABLE, 0x00),
                    *reg.LEAVE_PRIVATE_PAGE,
                    (reg.SYSTEM_INTERRUPT_CLEAR, 0x01),
                )
            )
            self._continuous = False

    def set_address(self, new_address: int) -> None:
        """Move the chip to ``new_address`` (kept until power-off or XSHUT low)."""
        check_address(new_address)
        with self._lock:
            self._write(reg.I2C_SLAVE_DEVICE_ADDRESS, new_address & 0x7F)
            old, self._address = self._address, new_address
            try:
                self._read(reg.IDENTIFICATION_MODEL_ID)
            except OSError as err:
                raise device_error(
                    f"{CHIP} moved from 0x{old:02X} but does not answer at "
                    f"0x{new_address:02X}: {err.strerror or err}",
                    err,
                ) from err
