"""The Microchip MCP9808 temperature sensor, read on request."""

from __future__ import annotations

from engine.hardware.chips.kind import ChipKind
from engine.hardware.config import ChipSpec
from engine.values.params import Choice, Param

KIND = ChipKind(
    ChipSpec(
        "mcp9808",
        "Microchip MCP9808 temperature, read on request",
        "i2c",
        "temperature",
        addresses=tuple(range(0x18, 0x20)),
        default_address=0x18,
        outputs={"celsius": "/sensors/temperature/c", "fahrenheit": "/sensors/temperature/f"},
        options=(
            Param(
                "resolution_c",
                Choice(("0.5", "0.25", "0.125", "0.0625")),
                "0.0625",
                "temperature step, degC",
            ),
        ),
    ),
)
