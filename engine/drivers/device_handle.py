"""A driver's claim on a bus: the object a driver (or its poller) holds to reach its chip.

:meth:`~engine.drivers.bus_manager.BusManager.claim` hands one out; every transaction it
submits runs under the device's name, so the manager can retry it, count it and refuse it
while the device is offline.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future
from typing import Generic, Protocol, TypeVar

from engine.drivers.bus_policy import Priority
from engine.drivers.device_stats import DeviceStats

__all__ = ["BusOwner", "DeviceHandle"]

BusT = TypeVar("BusT")
BusT_co = TypeVar("BusT_co", covariant=True)
T = TypeVar("T")


class BusOwner(Protocol[BusT_co]):
    """What a handle needs from the bus manager that issued it."""

    def place(self, address: int | None) -> str: ...

    def is_online(self, device: str) -> bool: ...

    def submit(
        self, device: str, fn: Callable[[BusT_co], T], *, priority: Priority = ...
    ) -> Future[T]: ...

    def call(
        self,
        device: str,
        fn: Callable[[BusT_co], T],
        *,
        priority: Priority = ...,
        timeout_s: float | None = ...,
    ) -> T: ...

    def stats(self) -> dict[str, DeviceStats]: ...

    def note_implausible(self, device: str, error: BaseException) -> None: ...

    def release(self, device: str) -> None: ...


class DeviceHandle(Generic[BusT]):
    """A driver's claim on a bus: submit transactions under its own name.

    ``address`` is the claimed address, for the driver's own ``bus.read_byte_data(address,
    ...)`` calls.
    """

    __slots__ = ("_address", "_manager", "_name")

    def __init__(self, manager: BusOwner[BusT], name: str, address: int | None) -> None:
        self._manager = manager
        self._name = name
        self._address = address

    @property
    def name(self) -> str:
        return self._name

    @property
    def address(self) -> int | None:
        return self._address

    @property
    def manager(self) -> BusOwner[BusT]:
        return self._manager

    @property
    def online(self) -> bool:
        return self._manager.is_online(self._name)

    def submit(self, fn: Callable[[BusT], T], *, priority: Priority = Priority.POLL) -> Future[T]:
        """Queue ``fn(bus)`` for this device; see :meth:`BusManager.submit`."""
        return self._manager.submit(self._name, fn, priority=priority)

    def call(
        self,
        fn: Callable[[BusT], T],
        *,
        priority: Priority = Priority.REQUEST,
        timeout_s: float | None = None,
    ) -> T:
        """Run ``fn(bus)`` and wait for its result (at most ``timeout_s`` real seconds).

        For a driver's setup (identity check, init sequence) and other places where the
        caller waits anyway; hence ``REQUEST`` priority. Never call it from a transaction.
        """
        return self._manager.call(self._name, fn, priority=priority, timeout_s=timeout_s)

    def stats(self) -> DeviceStats:
        return self._manager.stats()[self._name]

    def note_implausible(self, error: BaseException) -> None:
        """Count a reading the driver refused after its transactions had succeeded."""
        self._manager.note_implausible(self._name, error)

    def release(self) -> None:
        self._manager.release(self._name)

    def __repr__(self) -> str:
        return f"<DeviceHandle {self._name} at {self._manager.place(self._address)}>"
