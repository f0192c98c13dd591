"""The chip kinds vest knows, one module each: everything the engine knows of a chip.

Each module declares ``KIND``: the chip's :class:`~engine.hardware.config.ChipSpec` (config
fields, options, addresses, role, readings), the check of its own fields, its identity
probe, how it is polled or which service it offers, how ``vest devices`` shows a reading,
which simulated model stands in for it and its rules across devices.
:func:`default_chips` builds the registry; adding a chip means its driver, its simulated
model, one module here, a line below, and its tests.
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
