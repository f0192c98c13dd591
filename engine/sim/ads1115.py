"""A register-level model of the TI ADS1115 16-bit delta-sigma ADC.

What it models, after the ADS111x data sheet (SBAS444, section 9):

- Four 16-bit registers behind a 2-bit address pointer: conversion (0x00), config (0x01),
  Lo_thresh (0x02) and Hi_thresh (0x03). A write transfer is the pointer byte, then the
  register's MSB and LSB; a read transfer returns the pointed register MSB first. The
  pointer does not auto-increment: longer reads repeat the register.
- Power-on values: config 0x8583 (idle, AIN0-AIN1, +/-2.048 V, single-shot, 128 SPS,
  comparator off), Lo_thresh 0x8000, Hi_thresh 0x7FFF, conversion 0.
- Single-shot mode (MODE=1): writing OS=1 starts one conversion that takes 1/DR seconds of
  clock time. Meanwhile OS reads 0 and the conversion register still holds the previous
  result; OS=1 written during a conversion has no effect. Other fields write through at
  once and read back as written, with OS=1 while idle.
- Continuous mode (MODE=0): a new result every 1/DR seconds, OS reads 0.
- All eight MUX settings (four differential pairs, four single-ended against GND), the six
  PGA full-scale ranges (codes 101..111 all mean +/-0.256 V) and two's complement output
  that clips at 0x7FFF and 0x8000.

What it simplifies: a conversion uses the inputs as they were when it started (the real
delta-sigma modulator averages over the conversion time), the internal oscillator is exact
unless ``conversion_time_factor`` says otherwise (the real one is within 10 %), there is
no noise or offset, and the comparator and the ALERT/RDY pin are not modelled (the
threshold registers only store their values).
"""

from __future__ import annotations

import math
import threading

from engine.clock import Clock
from engine.drivers.ads1115_registers import (
    CODE_MAX,
    CODE_MIN,
    CONFIG,
    CONFIG_POWER_ON,
    CONVERSION,
    DATA_RATES_SPS,
    DR_SHIFT,
    HI_THRESH,
    INPUT_MARGIN_V,
    LO_THRESH,
    MODE_SINGLE_SHOT,
    MUX_INPUTS,
    MUX_SHIFT,
    OS,
    PGA_FULL_SCALE_V,
    PGA_SHIFT,
    POINTER_MASK,
)
from engine.sim.i2c_bus import SimI2CDevice


def volts_to_code(volts: float, full_scale_v: float) -> int:
    """The ideal output code for a differential input, clipped at the full scale."""
    code = math.floor(volts / full_scale_v * 32768 + 0.5)
    return max(CODE_MIN, min(CODE_MAX, code))


class SimADS1115(SimI2CDevice):
    """An ADS1115 whose four inputs are set in volts against GND.

    ``supply_v`` is VDD; inputs beyond GND - 0.3 V .. VDD + 0.3 V would damage the chip,
    so setting one is a ``ValueError``. ``conversion_time_factor`` scales the conversion
    time: 1.1 is an oscillator at the slow end of its 10 % tolerance, larger a faulty one.
    """

    def __init__(
        self,
        clock: Clock,
        address: int = 0x48,
        *,
        supply_v: float = 3.3,
        conversion_time_factor: float = 1.0,
    ) -> None:
        super().__init__(address)
        if not 2.0 <= supply_v <= 5.5:
            raise ValueError(f"ADS1115 supply {supply_v} V is outside 2.0..5.5 V")
        if not conversion_time_factor > 0:
            raise ValueError(f"conversion_time_factor {conversion_time_factor} must be positive")
        self._lock = threading.RLock()  # inputs move on another thread than the bus
        self._clock = clock
        self._supply_v = supply_v
        self._time_factor = conversion_time_factor
        self._inputs_v = [0.0, 0.0, 0.0, 0.0]
        self._pointer = CONVERSION
        self._config = CONFIG_POWER_ON & ~OS
        self._lo_thresh = 0x8000
        self._hi_thresh = 0x7FFF
        self._conversion = 0
        self._busy_until_s: float | None = None
        self._pending_code = 0
        self._next_continuous_s: float | None = None
        self.conversions = 0

    # -- physical side ------------------------------------------------------------------
    def set_input_volts(self, channel: int, volts: float) -> None:
        """Drive input AIN``channel`` (0..3) to ``volts`` against GND."""
        if not 0 <= channel <= 3:
            raise ValueError(f"ADS1115 channel {channel} is outside 0..3")
        low, high = -INPUT_MARGIN_V, self._supply_v + INPUT_MARGIN_V
        if not low <= volts <= high:
            raise ValueError(
                f"ADS1115 AIN{channel} at {volts} V is outside its absolute maximum "
                f"{low:.1f}..{high:.1f} V"
            )
        with self._lock:
            self._update()
            self._inputs_v[channel] = float(volts)

    @property
    def converting(self) -> bool:
        """True while a single-shot conversion is under way (OS reads 0)."""
        with self._lock:
            self._update()
            return self._busy_until_s is not None

    # -- wire side ----------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if not data:
            return
        with self._lock:
            self._update()
            self._pointer = data[0] & POINTER_MASK
            if len(data) < 3:
                return  # a pointer write (a lone MSB is not latched)
            value = data[1] << 8 | data[2]
            if self._pointer == CONFIG:
                self._write_config(value)
            elif self._pointer == LO_THRESH:
                self._lo_thresh = value
            elif self._pointer == HI_THRESH:
                self._hi_thresh = value
            # the conversion register is read-only

    def read(self, length: int) -> bytes:
        with self._lock:
            self._update()
            value = self._register(self._pointer)
        pair = bytes([value >> 8, value & 0xFF])
        return (pair * (length // 2 + 1))[:length]

    # -- chip internals -----------------------------------------------------------------
    def _register(self, pointer: int) -> int:
        if pointer == CONVERSION:
            return self._conversion & 0xFFFF
        if pointer == CONFIG:
            converting = self._busy_until_s is not None or self._next_continuous_s is not None
            return self._config | (0 if converting else OS)
        if pointer == LO_THRESH:
            return self._lo_thresh
        return self._hi_thresh

    def _period_s(self) -> float:
        return self._time_factor / DATA_RATES_SPS[(self._config >> DR_SHIFT) & 0x07]

    def _code_now(self) -> int:
        positive, negative = MUX_INPUTS[(self._config >> MUX_SHIFT) & 0x07]
        volts = self._inputs_v[positive] - (
            self._inputs_v[negative] if negative is not None else 0.0
        )
        return volts_to_code(volts, PGA_FULL_SCALE_V[(self._config >> PGA_SHIFT) & 0x07])

    def _write_config(self, value: int) -> None:
        start = bool(value & OS)
        self._config = value & ~OS
        if self._config & MODE_SINGLE_SHOT:
            self._next_continuous_s = None
            if start and self._busy_until_s is None:
                self._pending_code = self._code_now()
                self._busy_until_s = self._clock.now() + self._period_s()
        elif self._next_continuous_s is None:
            self._busy_until_s = None
            self._next_continuous_s = self._clock.now() + self._period_s()

    def _update(self) -> None:
        now = self._clock.now()
        if self._busy_until_s is not None and now >= self._busy_until_s:
            self._conversion = self._pending_code
            self._busy_until_s = None
            self.conversions += 1
        if self._next_continuous_s is not None and now >= self._next_continuous_s:
            period = self._period_s()
            missed = math.floor((now - self._next_continuous_s) / period) + 1
            self._conversion = self._code_now()
            self._next_continuous_s += missed * period
            self.conversions += missed
