"""A bit-level model of the Microchip MCP3008 8-channel 10-bit SPI ADC.

What it models, after the MCP3004/3008 data sheet (DS21295, sections 5 and 6):

- A frame begins at the first 1 clocked in on DIN while chip select is low (the start
  bit), so leading zeros are allowed. Then SGL/DIFF, D2, D1, D0 choose the input; one more
  clock completes the sample; DOUT then drives a low null bit and the 10-bit result MSB
  first, then again LSB first (B1..B9), then zeros. Before the null bit DOUT floats.
- A frame without a start bit leaves DOUT floating the whole time: the answer is garbage.
- Single-ended inputs CH0..CH7 and the eight differential pairs (IN+ below IN- reads 0).
- Code = floor(1024 * VIN / VREF), 0..1023.
- SPI modes 0,0 and 1,1 (modes 0 and 3); a clock above the chip's maximum for its supply
  (1.35 MHz at 2.7 V, 3.6 MHz at 5 V, interpolated linearly between) corrupts the answer.

What it simplifies: the input is sampled at the start bit rather than over the sample
window, there is no noise, offset or gain error, and the slow-clock limit (the sample
capacitor droops below about 10 kHz) is not modelled.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from engine.drivers.mcp3008_registers import (
    CHANNELS,
    CODE_COUNT,
    CODE_MAX,
    DIFFERENTIAL_PAIRS,
    MAX_CLOCK_AT_2V7_HZ,
    MAX_CLOCK_AT_5V_HZ,
    SPI_MODES,
    VDD_MAX_V,
    VDD_MIN_V,
    VREF_MIN_V,
)
from engine.sim.spi_bus import Bit, SimSpiDevice


def max_clock_hz(vdd_v: float) -> float:
    """The highest SPI clock the data sheet allows at supply ``vdd_v`` (2.7..5.5 V)."""
    fraction = (min(max(vdd_v, VDD_MIN_V), 5.0) - VDD_MIN_V) / (5.0 - VDD_MIN_V)
    return MAX_CLOCK_AT_2V7_HZ + fraction * (MAX_CLOCK_AT_5V_HZ - MAX_CLOCK_AT_2V7_HZ)


class SimMCP3008(SimSpiDevice):
    """An MCP3008 whose eight inputs are set in volts against VSS."""

    def __init__(self, *, vref_v: float = 3.3, vdd_v: float = 3.3) -> None:
        if not VDD_MIN_V <= vdd_v <= VDD_MAX_V:
            raise ValueError(f"MCP3008 supply {vdd_v} V is outside {VDD_MIN_V}..{VDD_MAX_V} V")
        if not VREF_MIN_V <= vref_v <= vdd_v:
            raise ValueError(f"MCP3008 VREF {vref_v} V is outside {VREF_MIN_V}..VDD ({vdd_v}) V")
        self.vref_v = vref_v
        self.vdd_v = vdd_v
        self._inputs_v = [0.0] * CHANNELS
        self.conversions = 0

    def set_input_volts(self, channel: int, volts: float) -> None:
        """Drive CH``channel`` (0..7) to ``volts`` against VSS."""
        if not 0 <= channel < CHANNELS:
            raise ValueError(f"MCP3008 channel {channel} is outside 0..{CHANNELS - 1}")
        if not -0.6 <= volts <= self.vdd_v + 0.6:
            raise ValueError(
                f"MCP3008 CH{channel} at {volts} V is outside its absolute maximum "
                f"-0.6..{self.vdd_v + 0.6:.1f} V"
            )
        self._inputs_v[channel] = float(volts)

    def code_for(self, volts: float) -> int:
        """The ideal code for an input of ``volts``."""
        return max(0, min(CODE_MAX, math.floor(CODE_COUNT * volts / self.vref_v)))

    def frame(self, mosi_bits: Sequence[int], *, mode: int, speed_hz: int) -> list[Bit]:
        if mode not in SPI_MODES or speed_hz > max_clock_hz(self.vdd_v):
            return [None] * len(mosi_bits)  # bits sampled on the wrong edge or too fast
        miso: list[Bit] = []
        start: int | None = None
        select: list[int] = []
        code = 0
        for index, bit in enumerate(mosi_bits):
            if start is None:
                miso.append(None)
                if bit:
                    start = index
                continue
            clock = index - start  # clocks after the start bit
            if clock <= 4:
                miso.append(None)
                select.append(bit)
                if clock == 4:
                    code = self._convert(select)
            elif clock == 5:
                miso.append(None)  # sample completes, DOUT still floating
            elif clock == 6:
                miso.append(0)  # null bit
            elif clock <= 16:
                miso.append(code >> (16 - clock) & 1)  # B9..B0
            elif clock <= 25:
                miso.append(code >> (clock - 16) & 1)  # B1..B9, LSB first
            else:
                miso.append(0)
        return miso

    def _convert(self, select: list[int]) -> int:
        single_ended, d2, d1, d0 = select
        selector = d2 << 2 | d1 << 1 | d0
        self.conversions += 1
        if single_ended:
            return self.code_for(self._inputs_v[selector])
        positive, negative = DIFFERENTIAL_PAIRS[selector]
        return self.code_for(self._inputs_v[positive] - self._inputs_v[negative])
