"""The MPR121 register map (data sheet Rev. 4, Table 1), shared by the driver and the
simulated chip.

Byte registers behind a pointer that auto-increments after every byte read or written.
"""

from __future__ import annotations

TOUCH_STATUS_L = 0x00  # ELE0..7
TOUCH_STATUS_H = 0x01  # ELE8..11, ELEPROX and the over-current flag
FILTERED_DATA_0 = 0x04  # ELE0 LSB, MSB; 13 little-endian 10-bit pairs up to 0x1D
BASELINE_0 = 0x1E  # upper 8 of the 10 baseline bits, one register per pad, to 0x2A
MHD_RISING = 0x2B  # baseline filter: MHDR, NHDR, NCLR, FDLR, MHDF, NHDF, NCLF, FDLF, NHDT..
TOUCH_THRESHOLD_0 = 0x41  # ELE0 touch threshold, ELE0 release threshold, ELE1 ... to 0x5A
DEBOUNCE = 0x5B
CONFIG1 = 0x5C  # FFI (first filter iterations), CDC (charge current, uA)
CONFIG2 = 0x5D  # CDT (charge time), SFI (second filter iterations), ESI (sample interval)
ECR = 0x5E  # electrode configuration: CL (7:6), ELEPROX_EN (5:4), ELE_EN (3:0)
GPIO_FIRST = 0x73
GPIO_LAST = 0x7A
SOFT_RESET = 0x80

SOFT_RESET_MAGIC = 0x63
CONFIG1_DEFAULT = 0x10  # after power-on or soft reset
CONFIG2_DEFAULT = 0x24  # after power-on or soft reset: the driver's identity check

ECR_CL_SHIFT = 6  # calibration lock: 00 keep, 01 no tracking, 10 load 5 MSB, 11 load all
ECR_CL_LOAD_5_MSB = 0b10 << ECR_CL_SHIFT  # tracking on, initial baseline from first data
ECR_ELEPROX_MASK = 0x30
ECR_ELE_MASK = 0x0F
ECR_STOP = 0x00

PADS = 12
DATA_MAX = 0x3FF  # filtered data and baseline are 10-bit
STATUS_PAD_MASK = (1 << PADS) - 1
# Above the pads: ELEPROX, two reserved bits and OVCF (over-current on REXT).
STATUS_NOT_PADS_MASK = 0xFFFF & ~STATUS_PAD_MASK
