"""The TI TCA9548A I2C multiplexer: a bus part, 8 channels behind one address."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.hardware.chips.kind import ChipKind, SimPlacement
from engine.hardware.config import ChipSpec, DeviceConfig


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    vest.add_mux(device)


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: bus.read_byte(address)


KIND = ChipKind(
    ChipSpec(
        "tca9548a",
        "TI TCA9548A 8-channel I2C multiplexer",
        "i2c",
        "mux",
        addresses=tuple(range(0x70, 0x78)),
        default_address=0x70,
    ),
    simulate=_simulate,
    probe=_probe,
)
