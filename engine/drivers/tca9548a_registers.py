"""The TCA9548A's one register, shared by the driver and the simulated chip.

The chip has one register, the control byte, written and read without a register pointer:
bit n connects channel n.
"""

from __future__ import annotations

ADDRESSES = range(0x70, 0x78)  # pins A0..A2
CHANNELS = 8
CONTROL_NONE = 0x00  # every channel disconnected (power-on and RESET)
