"""Pollers (the paper's "hardware nodes"): each polled device read at its rate, staged.

A :class:`Poller` owns one device's driver. At its rate it reads the device through the
device's bus-manager handle and stages what it read onto the blackboard. What a reading
is comes from the chip's kind (:mod:`engine.hardware.chips`, its ``poll``): touch pads
and "any", each force pad's newtons through its calibration, a range in mm (``None``
when nothing is in range), one event per gesture.

Two ways to run them, same code:

- as scheduler hooks (``poller(now_s)`` polls when due, on drift-free deadlines): inline,
  deterministic, for a :class:`~engine.clock.VirtualClock` with ``threaded=False`` bus
  managers (``vest run --fast``, tests). On a
  :class:`~engine.hardware.branching_clock.BranchingClock` each poll's waits stay in its branch;
- on threads (:class:`PollerThreads`), one per poller, for the robot.

Both are :mod:`engine.periodic`'s runners: a poller is a worker that says when it is due.

A device that fails is not the end: the poller drops its driver, stages the readings of a
device that senses nothing (no pad touched, no force, nothing in range) so that a stale
"touched" does not keep a behavior firing, and ``/devices/<name>/ok`` goes false (the bus
manager's offline mark, or :attr:`Poller.offline_after` failed polls in a row). Every due
poll tries again; the bus manager refuses polls of an offline device without touching the
bus until its next re-probe. When the device answers, a new driver is made (identity check,
init: a replugged chip starts from power-on) and the readings flow again. A VL53L0X on an
XSHUT line that no longer answers at its address (power-cycled, it is back at 0x29) is
rebooted through its line and moved back by its :class:`~engine.hardware.xshut.XshutChain`.
"""

from __future__ import annotations

import logging
import math
import threading
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from typing import Any, Generic, TypeVar

from engine.blackboard.board import Blackboard
from engine.clock import Clock
from engine.drivers.bus_errors import describe_exception
from engine.drivers.bus_manager import DeviceHandle
from engine.drivers.device_errors import ImplausibleReadingError
from engine.hardware.branching_clock import branch_of
from engine.hardware.chips import ChipRegistry, default_chips
from engine.hardware.config import DeviceConfig
from engine.hardware.device_health import DeviceHealth
from engine.hardware.readings import PollSetup, Staged
from engine.hardware.xshut import XshutChain
from engine.periodic import WorkerHook, WorkerThread

_log = logging.getLogger("vest.pollers")

D = TypeVar("D")


class Poller(Generic[D]):
    """Reads one device every ``1 / rate_hz`` seconds and stages what it read.

    ``connect()`` makes the driver (identity check and init); ``read(driver)`` reads it and
    returns the writes to stage; ``rest`` are the writes that say "this device senses
    nothing", staged when it stops working; ``release(driver)``, where given, lets the chip
    rest when the robot stops (:meth:`release`). ``offline_after`` failed polls in a row
    mark the device not ok even when the bus still answers (a chip answering nonsense).
    """

    def __init__(
        self,
        name: str,
        *,
        rate_hz: float,
        clock: Clock,
        blackboard: Blackboard,
        health: DeviceHealth,
        connect: Callable[[], D],
        read: Callable[[D], Sequence[Staged]],
        rest: Sequence[Staged] = (),
        release: Callable[[D], None] | None = None,
        offline_after: int = 3,
    ) -> None:
        if not rate_hz > 0:
            raise ValueError(f"poller {name!r}: rate_hz must be positive, got {rate_hz}")
        self.name = name
        self.rate_hz = rate_hz
        self.clock = clock
        self.blackboard = blackboard
        self.health = health
        self._connect = connect
        self._read = read
        self.rest = tuple(rest)
        self._release = release
        self.offline_after = offline_after
        self.driver: D | None = None
        self.origin_s: float | None = None  # the first poll sets the phase
        self.period_index = 0
        self.polls = 0
        self.failures = 0
        self.consecutive_failures = 0
        self.last_error: str | None = None
        self._resting = False
        self._lock = threading.Lock()  # one poll at a time (a hook and `vest devices`)
        self._hook = WorkerHook(self)

    def __repr__(self) -> str:
        return f"<Poller {self.name} {self.rate_hz:g} Hz>"

    @property
    def period_s(self) -> float:
        return 1.0 / self.rate_hz

    @property
    def next_due_s(self) -> float:
        """When the next poll is due (clock seconds); at once before the first poll."""
        if self.origin_s is None:
            return float("-inf")
        return self.origin_s + self.period_index * self.period_s

    # -- as a worker (engine.periodic): a scheduler hook inline, a thread for the robot ----
    def __call__(self, now_s: float) -> None:
        """Poll if due at ``now_s`` (clock seconds); a scheduler hook.

        The first call sets the phase, so the polls fall on the scheduler's steps.
        """
        self._hook(now_s)

    def due_s(self) -> float:
        return self.next_due_s

    def run(self, now_s: float) -> None:
        """One poll, due at ``now_s``, inside the clock's branch when inline."""
        with branch_of(self.clock):
            self.poll_once()
        self._advance(now_s)

    def _advance(self, now_s: float) -> None:
        """Move to the next deadline after ``now_s`` (skipping any that were missed)."""
        if self.origin_s is None:
            self.origin_s = now_s
        self.period_index = max(
            self.period_index + 1, math.floor((now_s - self.origin_s) / self.period_s + 1e-9) + 1
        )

    # -- one poll ------------------------------------------------------------------------
    def poll_once(self) -> bool:
        """Read the device once and stage what it read; False when it failed."""
        with self._lock:
            self.polls += 1
            try:
                if self.driver is None:
                    self.driver = self._connect()
                writes = self._read(self.driver)
            except Exception as error:  # a failing device must never stop the robot
                self._failed(error)
                return False
            if self.consecutive_failures:
                _log.info(
                    "%s answers again after %d failed polls", self.name, self.consecutive_failures
                )
            self.consecutive_failures = 0
            if not self.health.driver_ok:
                self.health.driver_status(True)
            self._resting = False
            self._stage(writes)
            return True

    def connect(self) -> None:
        """Make the driver now (identity check and init); raises what that raised."""
        with self._lock:
            if self.driver is None:
                self.driver = self._connect()

    def release(self) -> None:
        """Let the chip rest as the robot stops (a range sensor stops ranging back to back)
        and drop the driver: a later poll connects again. A chip that cannot be told (it
        no longer answers) is left as it is, and said in the log."""
        with self._lock:
            driver, self.driver = self.driver, None
            if driver is None or self._release is None:
                return
            try:
                self._release(driver)
            except Exception as error:  # stopping must go on whatever one chip does
                _log.warning("%s: not released at stop: %s", self.name, describe_exception(error))

    def read_now(self, *, fresh: bool = False) -> list[Staged]:
        """Read once without staging (for ``vest devices``); raises what the read raised.

        ``fresh`` makes a new driver first, so the chip's identity is checked again.
        """
        with self._lock:
            if fresh or self.driver is None:
                self.driver = None
                self.driver = self._connect()
            try:
                return list(self._read(self.driver))
            except Exception:
                self.driver = None
                raise

    def _failed(self, error: BaseException) -> None:
        self.driver = None  # a replugged chip starts from power-on: connect again
        self.failures += 1
        self.consecutive_failures += 1
        why = describe_exception(error)
        self.last_error = why
        if self.consecutive_failures == 1:  # once per streak, not at every poll
            if not isinstance(error, OSError):  # a driver bug: say so loudly, keep going
                _log.error("%s: poll failed with %s", self.name, why)
            else:
                _log.warning("%s: %s", self.name, why)
        if self.consecutive_failures >= self.offline_after:
            self.health.driver_status(False, why)
        if not self.health.ok and not self._resting:
            _log.warning("%s is offline; its readings say it senses nothing", self.name)
            self._resting = True
            self._stage(self.rest)

    def _stage(self, writes: Iterable[Staged]) -> None:
        for write in writes:
            if write.event:
                self.blackboard.stage_event(write.key, write.value)
            else:
                self.blackboard.stage(write.key, write.value)


POLL_MARGIN_S = 0.003
"""How long before the trees' deadline a threaded poll aims to have staged its reading."""
POLL_DURATION_WINDOW = 16


class _PollAhead:
    """A poller as a thread's worker: each poll starts early by the longest recent poll,
    so the reading is staged at the trees' deadline rather than just after it."""

    def __init__(self, poller: Poller[Any], clock: Clock) -> None:
        self.poller = poller
        self.clock = clock
        self.name = f"poller-{poller.name}"
        self._durations_s: deque[float] = deque(maxlen=POLL_DURATION_WINDOW)

    def due_s(self) -> float:
        if self.poller.origin_s is None:
            self.poller.origin_s = self.clock.now()
        lead_s = max(self._durations_s, default=0.0) + POLL_MARGIN_S
        return self.poller.next_due_s - lead_s

    def run(self, now_s: float) -> None:
        self.poller.poll_once()
        finished_s = self.clock.now()
        self._durations_s.append(finished_s - now_s)
        self.poller._advance(finished_s)


class PollerThreads:
    """Runs pollers on threads of their own (:class:`~engine.periodic.WorkerThread`), each
    at its rate, until :meth:`stop`.

    Each thread waits on ``clock`` for its own stop event, so a
    :class:`~engine.clock.VirtualClock` drives the threads as a real clock does, and
    stopping the scheduler never cuts short a driver's sleep inside a poll (which made
    the devices look offline after Ctrl-C).
    """

    def __init__(self, pollers: Sequence[Poller[Any]], clock: Clock) -> None:
        self.pollers = list(pollers)
        self.clock = clock
        self._workers: list[WorkerThread] = []

    def start(self, origin_s: float | None = None) -> None:
        """Start one thread per poller.

        ``origin_s`` is the trees' first deadline (clock seconds): each poller then reads
        its device so that the reading is staged just before the trees' deadlines rather
        than just after them, which would cost the reading a whole tree period.
        """
        if self._workers:
            return
        for poller in self.pollers:
            if origin_s is not None:
                poller.origin_s, poller.period_index = origin_s, 0
            worker = WorkerThread(_PollAhead(poller, self.clock), self.clock)
            self._workers.append(worker)
            worker.start()

    def stop(self) -> None:
        """Ask every thread to end and wait for them (the workers' one join policy)."""
        for worker in self._workers:
            worker.stop()
        self._workers.clear()

    @property
    def running(self) -> bool:
        return any(worker.running for worker in self._workers)


# -- the pollers of each role -------------------------------------------------------------------
def make_poller(
    device: DeviceConfig,
    handle: DeviceHandle[Any],
    *,
    clock: Clock,
    blackboard: Blackboard,
    health: DeviceHealth,
    chain: XshutChain | None = None,
    chips: ChipRegistry | None = None,
) -> Poller[Any]:
    """The poller for a polled device of the config (touch, force, range, gesture).

    ``chain``: the XSHUT chain of a VL53L0X on one, which brings the chip back when it no
    longer answers at its address.
    """
    kind = (chips or default_chips()).get(device.chip)
    if kind is None or kind.poll is None or device.rate_hz is None:
        raise ValueError(f"device {device.name!r} ({device.chip}) is not polled")
    parts = kind.poll(PollSetup(device, handle, clock, chain))

    def read_counted(driver: Any) -> Sequence[Staged]:
        try:
            return parts.read(driver)
        except ImplausibleReadingError as error:  # found after the bus transactions
            handle.note_implausible(error)
            raise

    return Poller(
        device.name,
        rate_hz=device.rate_hz,
        clock=clock,
        blackboard=blackboard,
        health=health,
        connect=parts.connect,
        read=read_counted,
        rest=parts.rest,
        release=parts.release,
    )
