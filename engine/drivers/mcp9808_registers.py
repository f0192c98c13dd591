"""The MCP9808 register map (data sheet DS25095, section 5), shared by the driver and the
simulated chip.

A 4-bit register pointer; 16-bit registers travel most significant byte first, the
resolution register is 8-bit.
"""

from __future__ import annotations

CONFIG = 0x01
T_UPPER = 0x02
T_LOWER = 0x03
T_CRIT = 0x04
T_AMBIENT = 0x05
MANUFACTURER_ID = 0x06
DEVICE_ID = 0x07
RESOLUTION = 0x08

MANUFACTURER_ID_VALUE = 0x0054
DEVICE_ID_VALUE = 0x04  # upper byte of register 0x07; the lower byte is the revision
DEVICE_REVISION = 0x00

CONFIG_THYST = 0x0600
CONFIG_SHDN = 0x0100
CONFIG_CRIT_LOCK = 0x0080
CONFIG_WIN_LOCK = 0x0040
CONFIG_LOCKS = CONFIG_CRIT_LOCK | CONFIG_WIN_LOCK
CONFIG_INT_CLEAR = 0x0020
CONFIG_WRITABLE = 0x07EF  # bits 10:0 except the read-only alert status (bit 4)

FLAG_CRIT = 0x8000  # TA >= TCRIT
FLAG_UPPER = 0x4000  # TA > TUPPER
FLAG_LOWER = 0x2000  # TA < TLOWER
SIGN = 0x1000
TEMPERATURE_MASK = 0x0FFF  # bits 11:0, 1/16 degC
TEMPERATURE_SIGNED_MASK = SIGN | TEMPERATURE_MASK  # 13-bit two's complement
LIMIT_MASK = 0x1FFC  # limits: 0.25 degC steps in bits 12:2

# Resolution register code -> (temperature step in degC, conversion time in seconds).
RESOLUTIONS: dict[int, tuple[float, float]] = {
    0b00: (0.5, 0.030),
    0b01: (0.25, 0.065),
    0b10: (0.125, 0.130),
    0b11: (0.0625, 0.250),
}
RESOLUTION_POWER_ON = 0b11

OPERATING_MIN_C = -40.0  # the chip's operating range: it reports nothing outside it
OPERATING_MAX_C = 125.0
