"""The MCP3008's command format and limits (Microchip data sheet DS21295, section 5),
shared by the driver and the simulated chip.

The chip has no registers: after a start bit the host clocks in SGL/DIFF and D2..D0, and
the chip answers a null bit and the 10-bit result, most significant bit first. As bytes
(the data sheet's figure 6-1): the start bit ends the first byte, SGL/DIFF and D2..D0 are
the top nibble of the second, and the answer's second byte holds the null bit just above
B9 B8.
"""

from __future__ import annotations

CHANNELS = 8
START_BIT = 0x01
SINGLE_ENDED = 0x80  # SGL/DIFF = 1, in the second byte's top bit
CHANNEL_SHIFT = 4
NULL_BIT = 0x04  # in the second answer byte, just above B9 B8
RESULT_HIGH_MASK = 0x03
CODE_COUNT = 1024
CODE_MAX = CODE_COUNT - 1

# Differential D2..D0 -> (IN+, IN-).
DIFFERENTIAL_PAIRS = {
    0b000: (0, 1),
    0b001: (1, 0),
    0b010: (2, 3),
    0b011: (3, 2),
    0b100: (4, 5),
    0b101: (5, 4),
    0b110: (6, 7),
    0b111: (7, 6),
}

SPI_MODES = (0, 3)  # SPI modes the chip samples correctly
VDD_MIN_V = 2.7
VDD_MAX_V = 5.5
VREF_MIN_V = 0.25
MAX_CLOCK_AT_2V7_HZ = 1_350_000  # the data sheet's limit at the lowest supply
MAX_CLOCK_AT_5V_HZ = 3_600_000
