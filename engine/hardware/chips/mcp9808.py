"""The Microchip MCP9808 temperature sensor, read on request."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.blackboard.catalogue import TEMPERATURE_C, TEMPERATURE_F
from engine.drivers import mcp9808_registers as registers
from engine.hardware.chips.kind import ChipKind, SimPlacement, expect_identity
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.hardware.sensor_services import TemperatureSensor
from engine.sim.mcp9808 import SimMCP9808
from engine.values.params import Choice, Param


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    model = SimMCP9808(vest.clock, device.address, temperature_c=vest.world.temperature_c)
    vest.attach_i2c(device, model)


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: expect_identity(
        "MCP9808 manufacturer ID",
        bus.read_i2c_block_data(address, registers.MANUFACTURER_ID, 2),
        [0x00, 0x54],
    )


KIND = ChipKind(
    ChipSpec(
        "mcp9808",
        "Microchip MCP9808 temperature, read on request",
        "i2c",
        "temperature",
        addresses=tuple(range(0x18, 0x20)),
        default_address=0x18,
        outputs={"celsius": TEMPERATURE_C, "fahrenheit": TEMPERATURE_F},
        options=(
            Param(
                "resolution_c",
                Choice(("0.5", "0.25", "0.125", "0.0625")),
                "0.0625",
                "temperature step, degC",
            ),
        ),
    ),
    simulate=_simulate,
    probe=_probe,
    service=TemperatureSensor,
)
