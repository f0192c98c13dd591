"""What the hardware services are made of: jobs on a device's bus-manager handle.

The services themselves are :mod:`engine.hardware.actuator_services` (the face LEDs, the
servo joints) and :mod:`engine.hardware.sensor_services` (temperature and ultrasound read
on request); a chip kind names its own (:mod:`engine.hardware.chips`). They implement
:mod:`engine.services.interfaces`: every method returns a
:class:`~engine.services.jobs.Job` at once; the work is one or a few transactions on the
device's bus manager at :attr:`~engine.drivers.bus_manager.Priority.REQUEST` priority,
ahead of routine polls. With ``threaded`` bus managers the transactions run on the bus's
worker and a job is done when its future is; inline they have run by the time the method
returns.

Drivers are made inside the first transaction that needs them (:class:`DriverSlot`), on
the bus itself, and made again after a failure (a replugged chip starts from power-on).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import CancelledError, Future
from typing import Any, Generic, TypeVar

from engine.clock import Clock
from engine.drivers.bus_manager import DeviceHandle, Priority
from engine.hardware.branching_clock import branch_of
from engine.hardware.config import DeviceConfig

D = TypeVar("D")
T = TypeVar("T")

"""Seconds between two tries to turn the LEDs off when the chip did not take it."""


class DriverSlot(Generic[D]):
    """A driver made on the bus inside the first transaction that needs it.

    ``make(bus)`` builds it (identity check, init); a transaction that fails drops it, so
    the next one starts from a fresh driver.
    """

    def __init__(self, make: Callable[[Any], D]) -> None:
        self._make = make
        self.driver: D | None = None

    def get(self, bus: Any) -> D:
        if self.driver is None:
            self.driver = self._make(bus)
        return self.driver

    def run(self, bus: Any, work: Callable[[D], T]) -> T:
        try:
            return work(self.get(bus))
        except Exception:
            self.driver = None
            raise


class OnDevice(Generic[D]):
    """A device a service drives: its handle, its driver slot, transactions on request."""

    def __init__(
        self,
        device: DeviceConfig,
        handle: DeviceHandle[Any],
        clock: Clock,
        make: Callable[[Any], D],
    ) -> None:
        self.device = device
        self.handle = handle
        self.clock = clock
        self.slot: DriverSlot[D] = DriverSlot(make)

    def submit(self, work: Callable[[D], T]) -> Future[T]:
        """Run ``work(driver)`` as one transaction, ahead of polls."""
        with branch_of(self.clock):
            return self.handle.submit(
                lambda bus: self.slot.run(bus, work), priority=Priority.REQUEST
            )

    def call(self, work: Callable[[D], T], timeout_s: float | None = 2.0) -> T:
        """Run ``work(driver)`` and wait for it (start-up, ``vest devices``)."""
        return self.handle.call(lambda bus: self.slot.run(bus, work), timeout_s=timeout_s)

    def connect(self) -> None:
        """Make the driver now (identity check and init); raises what that raised."""
        self.call(lambda driver: None)


# -- jobs ------------------------------------------------------------------------------------
class FutureResultJob:
    """A transaction's future as a Job, its result passed through ``convert``."""

    def __init__(self, future: Future[Any], convert: Callable[[Any], Any] = lambda v: v) -> None:
        self._future = future
        self._convert = convert
        self._cancelled = False

    def done(self) -> bool:
        return self._cancelled or self._future.done()

    def error(self) -> BaseException | None:
        if self._cancelled:
            return CancelledError("cancelled")
        if not self._future.done():
            return None
        if self._future.cancelled():
            return CancelledError("cancelled")
        return self._future.exception()

    def result(self) -> Any:
        if self.error() is not None or not self._future.done():
            return None
        return self._convert(self._future.result())

    def cancel(self) -> None:
        if not self.done():
            self._future.cancel()
            self._cancelled = True


class TimedFutureJob(FutureResultJob):
    """A command's future, then ``seconds`` on the clock (lit for a while, a servo moving)."""

    def __init__(self, future: Future[Any], clock: Clock, seconds: float) -> None:
        super().__init__(future)
        self._clock = clock
        self.finishes_at_s = clock.now() + max(0.0, seconds)

    def done(self) -> bool:
        if not super().done():
            return False
        if self.error() is not None:
            return True
        return self._clock.now() >= self.finishes_at_s


# -- LEDs --------------------------------------------------------------------------------------
