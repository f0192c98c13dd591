"""The Devantech SRF02 ultrasonic range finder, read on request."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.blackboard.catalogue import ULTRASOUND_CM
from engine.drivers import srf02_registers as registers
from engine.hardware.chips.kind import ChipKind, SimPlacement, expect_identity
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.hardware.sensor_services import UltrasoundSensor
from engine.sim.srf02 import SimSRF02


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    vest.attach_i2c(device, SimSRF02(vest.clock, device.address))


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: expect_identity(
        "SRF02 register 1", bus.read_byte_data(address, registers.UNUSED), registers.UNUSED_VALUE
    )


KIND = ChipKind(
    ChipSpec(
        "srf02",
        "Devantech SRF02 ultrasonic range, read on request",
        "i2c",
        "ultrasound",
        addresses=tuple(range(0x70, 0x78)),  # 0x78..0x7F are reserved on I2C
        default_address=0x70,
        outputs={"range": ULTRASOUND_CM},
    ),
    simulate=_simulate,
    probe=_probe,
    service=UltrasoundSensor,
)
