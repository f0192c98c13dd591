"""The XYZ Interactive ZX Sensor's I2C register map (version 1), shared by the driver and
the simulated chip.

Byte registers behind a pointer that auto-increments.
"""

from __future__ import annotations

ADDRESSES = (0x10, 0x11)

STATUS = 0x00
STATUS_DAV = 1 << 0  # new position data
STATUS_OVF = 1 << 1  # brightness overflow (unused, reads 0)
STATUS_SWP = 1 << 2  # swipe gesture available
STATUS_HOVER = 1 << 3  # hover gesture available
STATUS_HVG = 1 << 4  # hover-move gesture available
STATUS_EDGE = 1 << 5  # edge detection (unused, reads 0)
STATUS_HB = 1 << 7  # heartbeat: toggles on every STATUS read
STATUS_GESTURES = STATUS_SWP | STATUS_HOVER | STATUS_HVG
DRE = 0x01  # data-ready (DR pin) enables
DRCFG = 0x02  # DR pin configuration
DRCFG_FORCE = 1 << 6  # clears itself
DRCFG_POWER_ON = 0x81
GESTURE = 0x04
GSPEED = 0x05
DCM = 0x06
XPOS = 0x08
ZPOS = 0x0A
LRNG = 0x0C
RRNG = 0x0E
REGVER = 0xFE
MODEL = 0xFF

MODEL_ID = 0x01  # XZ01
REGISTER_MAP_VERSION = 0x01
MAX_POSITION = 240

# The engine's gesture name -> (GESTURE register value, STATUS bit that announces it).
GESTURES = {
    "swipe_right": (0x01, STATUS_SWP),
    "swipe_left": (0x02, STATUS_SWP),
    "swipe_up": (0x03, STATUS_SWP),
    "hover": (0x05, STATUS_HOVER),
    "hover_left": (0x06, STATUS_HVG),
    "hover_right": (0x07, STATUS_HVG),
    "hover_up": (0x08, STATUS_HVG),
}
