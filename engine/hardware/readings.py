"""What a poll makes: the blackboard writes of one reading, and how a chip is polled.

A chip kind that is polled (:mod:`engine.hardware.chips`) gives the three parts of a poller
(:class:`PollParts`): how to connect its driver, how one reading becomes writes, the
writes that say "this device senses nothing" while it is offline, and what its driver does
when the robot stops.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from engine.clock import Clock
from engine.drivers.bus_manager import DeviceHandle
from engine.hardware.config import DeviceConfig
from engine.hardware.xshut import XshutChain


@dataclass(frozen=True)
class Staged:
    """One blackboard write a poll makes: ``key = value``, or an event when ``event``."""

    key: str
    value: Any
    event: bool = False


@dataclass(frozen=True)
class PollParts:
    """How a chip kind is polled."""

    connect: Callable[[], Any]
    """The driver made on the device's handle (identity check and init)."""
    read: Callable[[Any], Sequence[Staged]]
    """One reading as writes."""
    rest: Sequence[Staged]
    """The writes staged while the device is offline."""
    release: Callable[[Any], None] | None = None
    """What the driver does when the robot stops, so the chip does not go on working for
    nobody (a range sensor stops ranging back to back); None: nothing to do."""


@dataclass(frozen=True)
class PollSetup:
    """What a chip kind's poller is made with."""

    device: DeviceConfig
    handle: DeviceHandle[Any]
    clock: Clock
    chain: XshutChain | None = None
    """The XSHUT chain of a VL53L0X on one, which brings the chip back when it no longer
    answers at its address."""

    @property
    def address(self) -> int:
        assert self.device.address is not None, f"{self.device.name} is an I2C device"
        return self.device.address


PollMaker = Callable[[PollSetup], PollParts]
