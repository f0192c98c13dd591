"""The VL53L0X measurement timing budget, worked out from its registers as ST's API does.

A measurement runs the enabled sequence steps (SYSTEM_SEQUENCE_CONFIG): TCC, MSRC and DSS
share one timeout, then the pre-range and the final range have their own. Each timeout is
in *macro periods* of its VCSEL period (2304 VCSEL periods of 1.655 ns PLL clocks), encoded
in 16 bits as ``(LSB << MSB) + 1``. The budget is the sum of the enabled steps' timeouts
plus ST's fixed overheads; setting a budget gives the final range whatever the other steps
leave. Pure functions of register values, after ``VL53L0X_get_/set_measurement_timing_
budget_micro_seconds`` of ST's API (1.0.2: 1320 us start overhead when setting, 1910 us
when reading back). Times in microseconds, as ST's registers and API count them.
"""

from __future__ import annotations

from dataclasses import dataclass

MIN_TIMING_BUDGET_US = 20_000
START_OVERHEAD_US = 1910  # reading the budget back
SET_START_OVERHEAD_US = 1320  # working out the final range for a budget
END_OVERHEAD_US = 960
MSRC_OVERHEAD_US = 660
TCC_OVERHEAD_US = 590
DSS_OVERHEAD_US = 690
PRE_RANGE_OVERHEAD_US = 660
FINAL_RANGE_OVERHEAD_US = 550
PLL_PERIOD_PS = 1655
MACRO_PERIOD_VCLKS = 2304


@dataclass(frozen=True)
class TimingRegisters:
    """The raw register values the budget depends on (page 0)."""

    sequence_config: int  # SYSTEM_SEQUENCE_CONFIG (0x01)
    pre_range_vcsel_period: int  # PRE_RANGE_CONFIG_VCSEL_PERIOD (0x50)
    msrc_timeout: int  # MSRC_CONFIG_TIMEOUT_MACROP (0x46), macro periods - 1
    pre_range_timeout: int  # PRE_RANGE_CONFIG_TIMEOUT_MACROP (0x51, 16-bit, encoded)
    final_range_vcsel_period: int  # FINAL_RANGE_CONFIG_VCSEL_PERIOD (0x70)
    final_range_timeout: int  # FINAL_RANGE_CONFIG_TIMEOUT_MACROP (0x71, 16-bit, encoded)

    @property
    def tcc(self) -> bool:
        return bool(self.sequence_config & 0x10)

    @property
    def dss(self) -> bool:
        return bool(self.sequence_config & 0x08)

    @property
    def msrc(self) -> bool:
        return bool(self.sequence_config & 0x04)

    @property
    def pre_range(self) -> bool:
        return bool(self.sequence_config & 0x40)

    @property
    def final_range(self) -> bool:
        return bool(self.sequence_config & 0x80)


PRE_RANGE_VCSEL_REGISTERS = range(5, 9)
"""Pre-range VCSEL periods the chip supports, 12..18 PLL clocks, as register values."""
FINAL_RANGE_VCSEL_REGISTERS = range(3, 7)
"""Final-range VCSEL periods the chip supports, 8..14 PLL clocks, as register values."""
MAX_TIMEOUT_EXPONENT = 15
"""The largest exponent (MSB) of an encoded timeout a chip ever holds (255 << 15 macro
periods is minutes: far past any budget)."""


def implausible(timing: TimingRegisters) -> str | None:
    """Why these register values cannot be a working chip's (a garbled read), or None."""
    if timing.pre_range_vcsel_period not in PRE_RANGE_VCSEL_REGISTERS:
        return f"pre-range VCSEL period register 0x50 reads {timing.pre_range_vcsel_period:#04x}"
    if timing.final_range_vcsel_period not in FINAL_RANGE_VCSEL_REGISTERS:
        return (
            f"final-range VCSEL period register 0x70 reads {timing.final_range_vcsel_period:#04x}"
        )
    for name, register, encoded in (
        ("pre-range", 0x51, timing.pre_range_timeout),
        ("final-range", 0x71, timing.final_range_timeout),
    ):
        if encoded >> 8 > MAX_TIMEOUT_EXPONENT:
            return f"{name} timeout register {register:#04x} reads {encoded:#06x}"
    return None


def vcsel_period_pclks(register: int) -> int:
    """The VCSEL period in PLL clocks from its register value (``(reg + 1) * 2``)."""
    return ((register + 1) & 0xFF) << 1


def macro_period_ns(vcsel_pclks: int) -> int:
    """One macro period in nanoseconds (rounded, as ST does) for a VCSEL period."""
    return (MACRO_PERIOD_VCLKS * vcsel_pclks * PLL_PERIOD_PS + 500) // 1000


def mclks_to_us(mclks: int, vcsel_pclks: int) -> int:
    """Macro periods to microseconds (ST's ``VL53L0X_calc_timeout_us``)."""
    return (mclks * macro_period_ns(vcsel_pclks) + 500) // 1000


def us_to_mclks(us: int, vcsel_pclks: int) -> int:
    """Microseconds to macro periods (ST's ``VL53L0X_calc_timeout_mclks``)."""
    period_ns = macro_period_ns(vcsel_pclks)
    return (us * 1000 + period_ns // 2) // period_ns


def decode_timeout(encoded: int) -> int:
    """Macro periods from a 16-bit timeout register, ``(LSB << MSB) + 1``."""
    return ((encoded & 0xFF) << ((encoded >> 8) & 0xFF)) + 1


def encode_timeout(mclks: int) -> int:
    """The 16-bit timeout register for ``mclks`` macro periods (0 for none)."""
    if mclks <= 0:
        return 0
    lsb, msb = mclks - 1, 0
    while lsb > 0xFF:
        lsb >>= 1
        msb += 1
    return (msb << 8) | lsb


def _steps_before_final_us(timing: TimingRegisters, start_overhead_us: int) -> int:
    """Overheads plus every enabled step's timeout but the final range's, in us."""
    pre_pclks = vcsel_period_pclks(timing.pre_range_vcsel_period)
    msrc_us = mclks_to_us(timing.msrc_timeout + 1, pre_pclks)
    used_us = start_overhead_us + END_OVERHEAD_US
    if timing.tcc:
        used_us += msrc_us + TCC_OVERHEAD_US
    if timing.dss:
        used_us += 2 * (msrc_us + DSS_OVERHEAD_US)
    elif timing.msrc:
        used_us += msrc_us + MSRC_OVERHEAD_US
    if timing.pre_range:
        pre_mclks = decode_timeout(timing.pre_range_timeout)
        used_us += mclks_to_us(pre_mclks, pre_pclks) + PRE_RANGE_OVERHEAD_US
    return used_us


def _pre_range_mclks(timing: TimingRegisters) -> int:
    return decode_timeout(timing.pre_range_timeout) if timing.pre_range else 0


def timing_budget_us(timing: TimingRegisters) -> int:
    """The measurement timing budget in microseconds that the registers give."""
    budget_us = _steps_before_final_us(timing, START_OVERHEAD_US)
    if timing.final_range:
        # The final range register counts the pre-range's macro periods too.
        final_mclks = decode_timeout(timing.final_range_timeout) - _pre_range_mclks(timing)
        final_pclks = vcsel_period_pclks(timing.final_range_vcsel_period)
        budget_us += mclks_to_us(final_mclks, final_pclks) + FINAL_RANGE_OVERHEAD_US
    return budget_us


def final_range_timeout_for(timing: TimingRegisters, budget_us: int) -> int:
    """The FINAL_RANGE_CONFIG_TIMEOUT_MACROP value that makes the budget ``budget_us``.

    ValueError when the budget is below ST's 20 ms minimum, when the other enabled steps
    leave no time for the final range, or when the final range is not enabled.
    """
    if budget_us < MIN_TIMING_BUDGET_US:
        raise ValueError(
            f"VL53L0X timing budget must be at least {MIN_TIMING_BUDGET_US} us, got {budget_us}"
        )
    if not timing.final_range:
        raise ValueError("VL53L0X timing budget: the final range step is not enabled")
    used_us = _steps_before_final_us(timing, SET_START_OVERHEAD_US) + FINAL_RANGE_OVERHEAD_US
    if used_us >= budget_us:
        raise ValueError(
            f"VL53L0X timing budget {budget_us} us leaves no time for the final range "
            f"(the other steps take {used_us} us)"
        )
    final_pclks = vcsel_period_pclks(timing.final_range_vcsel_period)
    final_mclks = us_to_mclks(budget_us - used_us, final_pclks) + _pre_range_mclks(timing)
    return encode_timeout(final_mclks)
