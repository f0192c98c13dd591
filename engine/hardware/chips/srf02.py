"""The Devantech SRF02 ultrasonic range finder, read on request."""

from __future__ import annotations

from engine.hardware.chips.kind import ChipKind
from engine.hardware.config import ChipSpec

KIND = ChipKind(
    ChipSpec(
        "srf02",
        "Devantech SRF02 ultrasonic range, read on request",
        "i2c",
        "ultrasound",
        addresses=tuple(range(0x70, 0x78)),  # 0x78..0x7F are reserved on I2C
        default_address=0x70,
        outputs={"range": "/sensors/ultrasound/cm"},
    ),
)
