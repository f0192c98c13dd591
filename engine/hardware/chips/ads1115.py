"""The TI ADS1115 16-bit ADC reading FSR 406 force pads (4 channels), polled."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.blackboard.catalogue import FORCE_SQUEEZE
from engine.drivers.ads1115 import ADS1115
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.force_pads import force_fields, force_poll, show_forces
from engine.hardware.chips.kind import ChipKind, SimPlacement
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.hardware.managed_buses import ManagedI2C
from engine.hardware.readings import PollParts, PollSetup
from engine.sim.ads1115 import SimADS1115
from engine.values.params import Choice, Param


def _pads(fields: ChipFields) -> dict[str, Any] | None:
    return force_fields(fields, channels=4)


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    vest.attach_i2c(device, SimADS1115(vest.clock, device.address))


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: bus.read_i2c_block_data(address, 0x01, 2)


def _poll(setup: PollSetup) -> PollParts:
    return force_poll(
        setup.device,
        lambda: ADS1115(
            ManagedI2C(setup.handle),
            address=setup.address,
            clock=setup.clock,
            **setup.device.options,
        ),
    )


KIND = ChipKind(
    ChipSpec(
        "ads1115",
        "TI ADS1115 16-bit ADC with FSR 406 force pads",
        "i2c",
        "force",
        addresses=tuple(range(0x48, 0x4C)),
        default_address=0x48,
        default_rate_hz=20.0,
        options=(
            Param("gain", Choice(("2/3", "1", "2", "4", "8", "16")), "1", "PGA gain"),
            Param(
                "data_rate_sps",
                Choice(("8", "16", "32", "64", "128", "250", "475", "860")),
                "860",
                "conversions per second (a reading takes about its inverse)",
            ),
        ),
        outputs={"squeeze": FORCE_SQUEEZE},
        fields=("pads", "squeeze_n"),
    ),
    _pads,
    simulate=_simulate,
    probe=_probe,
    poll=_poll,
    show=show_forces,
)
