"""The ADS1115 register map (ADS111x data sheet SBAS444, section 9), shared by the driver
and the simulated chip.

Four 16-bit registers behind a 2-bit address pointer, most significant byte first.
"""

from __future__ import annotations

# Pointer register values.
CONVERSION = 0x00
CONFIG = 0x01
LO_THRESH = 0x02
HI_THRESH = 0x03
POINTER_MASK = 0x03

# Config register fields.
CONFIG_POWER_ON = 0x8583  # idle, AIN0-AIN1, +/-2.048 V, single-shot, 128 SPS, comparator off
OS = 0x8000  # write: start a single conversion; read: 1 = idle, 0 = converting
MUX_SHIFT = 12
MUX_SINGLE_ENDED = 0b100  # 100..111: AIN0..AIN3 against GND
PGA_SHIFT = 9
MODE_SINGLE_SHOT = 0x0100
DR_SHIFT = 5
COMP_QUE_DISABLE = 0x0003

# MUX code -> (positive input, negative input or None for GND).
MUX_INPUTS: dict[int, tuple[int, int | None]] = {
    0b000: (0, 1),
    0b001: (0, 3),
    0b010: (1, 3),
    0b011: (2, 3),
    0b100: (0, None),
    0b101: (1, None),
    0b110: (2, None),
    0b111: (3, None),
}
# PGA code -> full-scale range in volts (+/-); codes 101..111 all mean +/-0.256 V.
PGA_FULL_SCALE_V = (6.144, 4.096, 2.048, 1.024, 0.512, 0.256, 0.256, 0.256)
PGA_GAINS = (2 / 3, 1, 2, 4, 8, 16)  # the gains of PGA codes 000..101
# DR code -> data rate in samples per second.
DATA_RATES_SPS = (8, 16, 32, 64, 128, 250, 475, 860)

CODE_MIN = -0x8000
CODE_MAX = 0x7FFF
INPUT_MARGIN_V = 0.3  # absolute maximum: GND - 0.3 V .. VDD + 0.3 V
