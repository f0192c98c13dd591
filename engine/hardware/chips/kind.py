"""A chip kind: what the robot config knows of one chip, and the registry of them all.

The BehaviorTree.CPP factory idea applied to hardware: each chip kind is declared in one
module of :mod:`engine.hardware.chips` (its :class:`~engine.hardware.config.ChipSpec` and
the check of its own structured fields), and :func:`engine.hardware.chips.default_chips`
gathers them into a :class:`ChipRegistry` object, handed to whoever needs it (no global).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from engine.clock import Clock
from engine.drivers.bus_manager import DeviceHandle
from engine.errors import DeviceError
from engine.files.problems import Mark, Problems
from engine.hardware.chips.fields import ChipFields
from engine.hardware.config import BusConfig, ChipSpec, DeviceConfig
from engine.hardware.readings import PollMaker, Staged
from engine.scenario.world import World
from engine.sim.i2c_bus import SimI2CBus, SimI2CDevice

FieldsCheck = Callable[[ChipFields], dict[str, Any] | None]
"""Checks a device's structured fields; returns the values for its DeviceConfig (e.g.
``{"pads": (...)}``), or None after adding each problem with its place."""


def no_fields(fields: ChipFields) -> dict[str, Any] | None:
    """A chip with no structured fields of its own."""
    return {}


class DevicesTogether(Protocol):
    """What a chip kind's rules across devices see: every bus and device of the config,
    the problems, and each device field's place."""

    buses: dict[str, BusConfig]
    devices: dict[str, DeviceConfig]

    @property
    def problems(self) -> Problems: ...

    def mark(self, device: DeviceConfig, field_name: str) -> Mark: ...


class DeviceService(Protocol):
    """A hardware service on one device: it connects (makes its driver) or raises."""

    def connect(self) -> None: ...


ServiceMaker = Callable[[DeviceConfig, DeviceHandle[Any], Clock], DeviceService]

TogetherCheck = Callable[[DevicesTogether, list[DeviceConfig]], None]
"""Rules between the devices of one chip kind and the rest of the config (adds problems)."""


class SimPlacement(Protocol):
    """Where a chip kind's simulated model goes: the simulated vest answers."""

    clock: Clock
    world: World

    def i2c_bus_for(self, device: DeviceConfig) -> SimI2CBus:
        """The simulated I2C bus the device is on (behind its mux, if any)."""
        ...

    def attach_i2c(self, device: DeviceConfig, model: SimI2CDevice) -> None:
        """Attach ``model`` at the device's address and keep it as the device's chip."""
        ...

    def keep(self, device: DeviceConfig, model: Any, bus: SimI2CBus | None = None) -> None:
        """Keep ``model`` as the device's chip (a model that attached itself)."""
        ...

    def add_mux(self, device: DeviceConfig) -> None: ...

    def add_spi(self, device: DeviceConfig) -> None: ...

    def add_maestro(self, device: DeviceConfig) -> None: ...


SimModel = Callable[[SimPlacement, DeviceConfig], None]
ShowReading = Callable[[DeviceConfig, Sequence[Staged]], str]
Probe = Callable[[int], Callable[[Any], object]]
"""Given the chip's address, a bus read of its identity (or of a harmless register) that
raises unless the chip is there: how a device is found and re-probed while offline."""


def expect_identity(what: str, got: object, wanted: object) -> None:
    """Raise when an identity register does not read as the datasheet says."""
    if got != wanted:
        raise DeviceError(f"{what} reads {got!r}, expected {wanted!r}")


"""Puts the register-level model that stands in for a chip into the simulated vest."""


@dataclass(frozen=True)
class ChipKind:
    """One kind of chip: its spec, the check of its structured fields, and the simulated
    model that stands in for it without hardware."""

    spec: ChipSpec
    check_fields: FieldsCheck = no_fields
    simulate: SimModel | None = None
    probe: Probe | None = None
    poll: PollMaker | None = None
    """For a polled chip: how its poller connects, reads and rests (engine.hardware.readings)."""
    list_lengths: tuple[tuple[str, int], ...] = ()
    """Readings that are lists, and how many items each holds (touch ``pads``: 12), so a
    tree's ``item:`` can be checked against the robot."""
    service: ServiceMaker | None = None
    """For a chip read on request or commanded (not the Maestro, which owns its port): the
    service on its device handle, placed by the chip's role (leds, temperature,
    ultrasound)."""
    check_together: TogetherCheck | None = None
    """Rules between this kind's devices and the others (the VL53L0X boot address, the
    PCA9685's All Call address)."""
    show: ShowReading | None = None
    """For a polled chip: one reading in words, as ``vest devices`` prints it."""

    @property
    def name(self) -> str:
        return self.spec.chip


class ChipRegistry:
    """Chip kinds by their config name (``chip: mpr121``)."""

    def __init__(self, kinds: list[ChipKind] | None = None) -> None:
        self._kinds: dict[str, ChipKind] = {}
        for kind in kinds or []:
            self.add(kind)

    def add(self, kind: ChipKind) -> None:
        if kind.name in self._kinds:
            raise ValueError(f"chip kind {kind.name!r} is registered twice")
        self._kinds[kind.name] = kind

    def get(self, name: str) -> ChipKind | None:
        return self._kinds.get(name)

    @property
    def names(self) -> list[str]:
        return list(self._kinds)

    def __iter__(self) -> Iterator[ChipKind]:
        return iter(self._kinds.values())
