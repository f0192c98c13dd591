"""Drivers on managed buses: every access one transaction of the bus manager.

A driver takes an ``smbus2.SMBus``-compatible bus and makes one register access after
another, sleeping on its clock in between where its chip needs time (an ADC conversion, a
time-of-flight measurement). :class:`ManagedI2C` is such a bus whose every access is one
transaction of the device's :class:`~engine.drivers.bus_manager.DeviceHandle`: the bus
manager retries it, counts it, refuses it while the device is offline, and between two
accesses the bus is free for the other devices, so a 33 ms measurement never holds the
bus for 33 ms. :class:`ManagedSpi` does the same for an ``spidev``-compatible node.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from engine.drivers.bus_manager import DeviceHandle, Priority
from engine.drivers.forwarding_bus import ForwardingI2C, call_on

T = TypeVar("T")

DEFAULT_WAIT_S = 2.0
"""How long (real seconds) a driver waits for one access of a busy threaded bus."""


class _OnHandle:
    """Each access is one transaction of ``handle``, at ``priority`` (:attr:`Priority.POLL`
    for pollers: refused while the device is offline), waiting at most ``wait_s`` real
    seconds for a busy threaded bus. Bus errors arrive as the manager raises them
    (:class:`~engine.errors.DeviceError` naming device, bus and errno in words)."""

    def __init__(
        self,
        handle: DeviceHandle[Any],
        *,
        priority: Priority = Priority.POLL,
        wait_s: float | None = DEFAULT_WAIT_S,
    ) -> None:
        self.handle = handle
        self.priority = priority
        self.wait_s = wait_s

    def _call(self, fn: Callable[[Any], T]) -> T:
        return self.handle.call(fn, priority=self.priority, timeout_s=self.wait_s)

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.handle!r}>"


class ManagedI2C(_OnHandle, ForwardingI2C):
    """An ``smbus2.SMBus``-compatible bus: each call is one transaction of its handle."""

    def _forward(self, method: str, *args: Any) -> Any:
        return self._call(lambda bus: call_on(bus, method, *args))

    def close(self) -> None:
        """Nothing to release: the bus belongs to its manager's owner."""


class ManagedSpi(_OnHandle):
    """An ``spidev.SpiDev``-compatible node: each exchange is one transaction of its handle."""

    @property
    def mode(self) -> int:
        return int(self._call(lambda spi: spi.mode))

    @mode.setter
    def mode(self, value: int) -> None:
        self._call(lambda spi: setattr(spi, "mode", value))

    @property
    def max_speed_hz(self) -> int:
        return int(self._call(lambda spi: spi.max_speed_hz))

    @max_speed_hz.setter
    def max_speed_hz(self, value: int) -> None:
        self._call(lambda spi: setattr(spi, "max_speed_hz", value))

    def xfer(self, values: Sequence[int], speed_hz: int = 0) -> list[int]:
        data = list(values)
        return self._call(lambda spi: spi.xfer(data, speed_hz))

    def xfer2(self, values: Sequence[int], speed_hz: int = 0) -> list[int]:
        data = list(values)
        return self._call(lambda spi: spi.xfer2(data, speed_hz))

    def readbytes(self, length: int) -> list[int]:
        return self._call(lambda spi: spi.readbytes(length))

    def writebytes(self, values: Sequence[int]) -> None:
        data = list(values)
        self._call(lambda spi: spi.writebytes(data))
