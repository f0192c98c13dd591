"""The NXP MPR121 capacitive touch chip: 12 pads, polled."""

from __future__ import annotations

from engine.hardware.chips.kind import ChipKind
from engine.hardware.config import ChipSpec
from engine.values.params import Integer, Param

KIND = ChipKind(
    ChipSpec(
        "mpr121",
        "NXP MPR121 capacitive touch, 12 pads",
        "i2c",
        "touch",
        addresses=tuple(range(0x5A, 0x5E)),
        default_address=0x5A,
        default_rate_hz=20.0,
        outputs={"pads": "/sensors/touch/pads", "any": "/sensors/touch/any"},
        options=(
            Param("touch_threshold", Integer(1, 255), 12, "touch threshold, counts"),
            Param("release_threshold", Integer(0, 255), 6, "release threshold, counts"),
        ),
    ),
)
