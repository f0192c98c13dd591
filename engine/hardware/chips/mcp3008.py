"""The Microchip MCP3008 10-bit SPI ADC reading FSR 406 force pads (8 channels), polled."""

from __future__ import annotations

from typing import Any

from engine.blackboard.catalogue import FORCE_SQUEEZE
from engine.drivers.mcp3008 import MCP3008
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.force_pads import force_fields, force_poll, show_forces
from engine.hardware.chips.kind import ChipKind, SimPlacement
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.hardware.managed_buses import ManagedSpi
from engine.hardware.readings import PollParts, PollSetup
from engine.values.params import Integer, Number, Param


def _pads(fields: ChipFields) -> dict[str, Any] | None:
    return force_fields(fields, channels=8)


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    vest.add_spi(device)


def _poll(setup: PollSetup) -> PollParts:
    return force_poll(
        setup.device, lambda: MCP3008(ManagedSpi(setup.handle), **setup.device.options)
    )


KIND = ChipKind(
    ChipSpec(
        "mcp3008",
        "Microchip MCP3008 10-bit SPI ADC with FSR 406 force pads",
        "spi",
        "force",
        default_rate_hz=20.0,
        options=(
            Param("vref_v", Number(0.25, 5.5, "V"), 3.3, "reference voltage"),
            Param("max_speed_hz", Integer(10_000, 3_600_000), 1_000_000, "SPI clock"),
        ),
        outputs={"squeeze": FORCE_SQUEEZE},
        fields=("pads", "squeeze_n"),
    ),
    _pads,
    simulate=_simulate,
    poll=_poll,
    show=show_forces,
)
