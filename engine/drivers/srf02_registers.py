"""The SRF02 register map and command codes (Devantech's technical documentation),
shared by the driver and the simulated chip.
"""

from __future__ import annotations

COMMAND = 0x00  # write: command; read: software revision (0xFF while ranging)
UNUSED = 0x01  # reads 0x80
RANGE_HIGH = 0x02
RANGE_LOW = 0x03
AUTOTUNE_MIN_HIGH = 0x04
AUTOTUNE_MIN_LOW = 0x05
REGISTERS = 6

# Commands, written to COMMAND.
RANGE_INCHES = 0x50
RANGE_CM = 0x51
RANGE_MICROSECONDS = 0x52
FAKE_RANGE_FIRST = 0x56
FAKE_RANGE_LAST = 0x58
BURST = 0x5C
RESTART_AUTOTUNE = 0x60

BUSY = 0xFF  # COMMAND reads this while ranging
UNUSED_VALUE = 0x80

RANGING_TIME_S = 0.066
MAX_RANGE_CM = 600  # the chip's 6 m; farther is "no echo", 0
POWER_UP_MIN_CM = 28.0  # the minimum range of a fresh chip ...
TUNED_MIN_CM = 16.0  # ... once it has tuned itself
