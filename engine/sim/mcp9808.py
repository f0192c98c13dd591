"""A register-level model of the Microchip MCP9808 digital temperature sensor.

What it models, after the MCP9808 data sheet (DS25095, section 5):

- A 4-bit register pointer (writes with pointer bits 7:4 set reach reserved test
  registers: here they read 0 and ignore data). 16-bit registers travel MSB first; the
  resolution register is 8-bit. The pointer does not auto-increment: longer reads repeat.
- Identity: manufacturer ID (0x06) = 0x0054, device ID/revision (0x07) = 0x0400.
- Ambient temperature (0x05): bit 15 TA >= TCRIT, bit 14 TA > TUPPER, bit 13 TA < TLOWER,
  bit 12 sign, bits 11:0 the temperature in 1/16 degC (13-bit two's complement). Reads 0
  until the first conversion after power-up.
- Continuous conversion: the register (flags included) is loaded once per conversion time
  of the selected resolution (register 0x08: 0.5 / 0.25 / 0.125 / 0.0625 degC take 30 / 65
  / 130 / 250 ms), quantized to that resolution by dropping low bits (toward minus
  infinity, as truncating two's complement does).
- Limit registers TUPPER (0x02), TLOWER (0x03), TCRIT (0x04): 0.25 degC steps in bits
  12:2, other bits read 0.
- CONFIG (0x01): SHDN (bit 8) stops conversions and the last result stays; the window
  lock (bit 6) freezes TUPPER/TLOWER and the critical lock (bit 7) freezes TCRIT, both
  until power-on reset, and while either is set SHDN cannot be set and THYST cannot be
  changed; interrupt clear (bit 5) reads 0.

What it simplifies: the ALERT output and its status bit (bit 4) are not modelled, flags
ignore THYST, a resolution change or wake-up restarts the conversion cycle at that moment,
and the temperature is exact (the real chip is within +/-0.25 degC typical).
"""

from __future__ import annotations

import math
import threading

from engine.clock import Clock
from engine.drivers.mcp9808_registers import (
    CONFIG,
    CONFIG_CRIT_LOCK,
    CONFIG_INT_CLEAR,
    CONFIG_LOCKS,
    CONFIG_SHDN,
    CONFIG_THYST,
    CONFIG_WIN_LOCK,
    CONFIG_WRITABLE,
    DEVICE_ID,
    DEVICE_ID_VALUE,
    DEVICE_REVISION,
    FLAG_CRIT,
    FLAG_LOWER,
    FLAG_UPPER,
    LIMIT_MASK,
    MANUFACTURER_ID,
    MANUFACTURER_ID_VALUE,
    OPERATING_MAX_C,
    OPERATING_MIN_C,
    RESOLUTION,
    RESOLUTION_POWER_ON,
    RESOLUTIONS,
    SIGN,
    T_AMBIENT,
    T_CRIT,
    T_LOWER,
    T_UPPER,
    TEMPERATURE_SIGNED_MASK,
)
from engine.sim.i2c_bus import SimI2CDevice

# Resolution code -> (step in 1/16 degC, conversion time in seconds).
_STEPS = {code: (round(step_c * 16), time_s) for code, (step_c, time_s) in RESOLUTIONS.items()}


def _signed13(word: int) -> int:
    word &= TEMPERATURE_SIGNED_MASK
    return word - 0x2000 if word & SIGN else word


class SimMCP9808(SimI2CDevice):
    """An MCP9808 in air at ``temperature_c`` degrees Celsius, converting on ``clock``."""

    def __init__(self, clock: Clock, address: int = 0x18, *, temperature_c: float = 22.0) -> None:
        super().__init__(address)
        self._lock = threading.RLock()  # the world model sets the temperature on its thread
        self._clock = clock
        self._temperature_c = self._checked(temperature_c)
        self._pointer = T_AMBIENT
        self._config = 0
        self._limits = {T_UPPER: 0, T_LOWER: 0, T_CRIT: 0}
        self._resolution = RESOLUTION_POWER_ON
        self._ambient = 0x0000
        self._cycle_start_s = clock.now()
        self.conversions = 0

    # -- physical side ------------------------------------------------------------------
    @property
    def temperature_c(self) -> float:
        """The air temperature at the chip, degrees Celsius (-40..125)."""
        return self._temperature_c

    @temperature_c.setter
    def temperature_c(self, value: float) -> None:
        checked = self._checked(value)
        with self._lock:
            self._update()  # conversions finished so far saw the old temperature
            self._temperature_c = checked

    @property
    def conversion_time_s(self) -> float:
        """Seconds per conversion at the current resolution."""
        return _STEPS[self._resolution][1]

    @staticmethod
    def _checked(value: float) -> float:
        if not OPERATING_MIN_C <= value <= OPERATING_MAX_C:
            raise ValueError(
                f"MCP9808 temperature {value} degC is outside its operating range "
                f"{OPERATING_MIN_C}..{OPERATING_MAX_C}"
            )
        return float(value)

    # -- wire side ----------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if not data:
            return
        with self._lock:
            self._update()
            self._pointer = data[0]
            payload = data[1:]
            if self._pointer == RESOLUTION and payload:
                self._resolution = payload[0] & 0x03
                self._cycle_start_s = self._clock.now()
            elif len(payload) >= 2:
                self._write_word(self._pointer, payload[0] << 8 | payload[1])

    def read(self, length: int) -> bytes:
        with self._lock:
            self._update()
            if self._pointer == RESOLUTION:
                return bytes([self._resolution]) * length
            word = self._read_word(self._pointer)
        return (bytes([word >> 8, word & 0xFF]) * (length // 2 + 1))[:length]

    # -- chip internals -----------------------------------------------------------------
    def _read_word(self, pointer: int) -> int:
        if pointer == CONFIG:
            return self._config
        if pointer in self._limits:
            return self._limits[pointer]
        if pointer == T_AMBIENT:
            return self._ambient
        if pointer == MANUFACTURER_ID:
            return MANUFACTURER_ID_VALUE
        if pointer == DEVICE_ID:
            return DEVICE_ID_VALUE << 8 | DEVICE_REVISION
        return 0  # RFU (0x00) and reserved registers

    def _write_word(self, pointer: int, value: int) -> None:
        if pointer == CONFIG:
            self._write_config(value)
        elif pointer == T_CRIT:
            if not self._config & CONFIG_CRIT_LOCK:
                self._limits[T_CRIT] = value & LIMIT_MASK
        elif pointer in (T_UPPER, T_LOWER) and not self._config & CONFIG_WIN_LOCK:
            self._limits[pointer] = value & LIMIT_MASK
        # TA, the IDs and reserved registers are read-only

    def _write_config(self, value: int) -> None:
        value &= CONFIG_WRITABLE & ~CONFIG_INT_CLEAR
        old = self._config
        locks = old & CONFIG_LOCKS
        new = value | locks  # locks clear only at power-on reset
        if locks:
            new = (new & ~CONFIG_THYST) | (old & CONFIG_THYST)
            if not old & CONFIG_SHDN:
                new &= ~CONFIG_SHDN  # cannot enter shutdown while locked
        if old & CONFIG_SHDN and not new & CONFIG_SHDN:
            self._cycle_start_s = self._clock.now()  # wakes up and starts converting
        self._config = new

    def _update(self) -> None:
        """Load the result of every conversion finished by now (the last one wins)."""
        if self._config & CONFIG_SHDN:
            return
        period_s = self.conversion_time_s
        # the small allowance keeps float rounding from losing a conversion on a boundary
        done = math.floor((self._clock.now() - self._cycle_start_s) / period_s + 1e-9)
        if done < 1:
            return
        self._cycle_start_s += done * period_s
        self._ambient = self._convert()
        self.conversions += done

    def _convert(self) -> int:
        step = _STEPS[self._resolution][0]
        sixteenths = math.floor(self._temperature_c * 16)
        sixteenths -= sixteenths % step  # drop the bits below the resolution
        word = sixteenths & TEMPERATURE_SIGNED_MASK
        if sixteenths >= _signed13(self._limits[T_CRIT]):
            word |= FLAG_CRIT
        if sixteenths > _signed13(self._limits[T_UPPER]):
            word |= FLAG_UPPER
        if sixteenths < _signed13(self._limits[T_LOWER]):
            word |= FLAG_LOWER
        return word
