"""What a poll makes: the blackboard writes of one reading, and how a chip is polled.

A chip kind that is polled (:mod:`engine.hardware.chips`) gives the three parts of a poller
(:data:`PollParts`): how to connect its driver, how one reading becomes writes, and the
writes that say "this device senses nothing" while it is offline.
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


PollParts = tuple[Callable[[], Any], Callable[[Any], Sequence[Staged]], Sequence[Staged]]
"""(connect, read, rest): the driver made on the device's handle, one reading as writes,
and the writes staged while the device is offline."""


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
