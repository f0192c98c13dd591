"""The chip kinds vest knows, one module each: the robot config's view of a chip.

:func:`default_chips` builds the registry the config checker uses. Adding a chip to the
config means one module here (its :class:`~engine.hardware.config.ChipSpec` and the
check of its own fields) and a line below.
"""

from __future__ import annotations

from engine.hardware.chips.kind import ChipKind, ChipRegistry


def default_chips() -> ChipRegistry:
    """Every chip kind vest ships with, in the order ``vest devices`` lists them."""
    from engine.hardware.chips import (
        ads1115,
        maestro,
        mcp3008,
        mcp9808,
        mpr121,
        pca9685,
        srf02,
        tca9548a,
        vl53l0x,
        zx_gesture,
    )

    modules = (
        mpr121,
        ads1115,
        mcp3008,
        vl53l0x,
        zx_gesture,
        srf02,
        mcp9808,
        pca9685,
        maestro,
        tca9548a,
    )
    return ChipRegistry([module.KIND for module in modules])


__all__ = ["ChipKind", "ChipRegistry", "default_chips"]
