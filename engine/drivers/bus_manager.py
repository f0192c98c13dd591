"""Bus managers: the one owner of each bus (the paper's "constitution" for buses, section 3).

Every access to an I2C, SPI or serial bus goes through the :class:`BusManager` that owns it.
A driver claims its address, then submits *transactions*: callables run against the bus
object (an ``smbus2.SMBus``-compatible bus, an ``spidev``-compatible object with ``xfer2``,
a pyserial port: the manager does not care which). The manager

- runs one transaction at a time, on-request reads (:attr:`Priority.REQUEST`) before routine
  polls (:attr:`Priority.POLL`), first come first served within a priority, and hands the
  caller a :class:`concurrent.futures.Future` (the paper's requesting nodes polled the
  manager for completion; ours wait on the future, or are called back);
- retries bus errors that a second try can fix (NACK, EIO, timeouts, EAGAIN) a bounded number
  of times, backing off through the injected clock, then fails with a
  :class:`~engine.drivers.bus_errors.TransactionFailedError` that says the errno in words,
  the device, the bus and the address;
- marks a device that keeps failing *offline* (``on_status(name, False)``), refuses its
  routine polls without touching the bus, re-probes it at a slow rate and brings it back
  (``on_status(name, True)``) once it answers, so one failing device never stops the others;
- keeps per-device statistics (:class:`DeviceStats`) for the debug tools.

Two ways to run: ``threaded=True`` (the robot) starts one worker thread per bus;
``threaded=False`` runs each transaction at once in the caller's thread with the same retry,
offline and statistics rules, for runs on a :class:`~engine.clock.VirtualClock` where a
worker thread would make the order of events depend on the machine.

Threaded, :meth:`BusManager.submit` never waits; :meth:`BusManager.call` waits for the
answer, and when the bus is idle runs the transaction in the calling thread, saving the
hand-off to the worker and back (tens of microseconds, most of the manager's cost). The
worker waits on the injected clock, so a :class:`~engine.clock.VirtualClock` drives it too.

This module is the worker. The parts: the queue (:mod:`~engine.drivers.job_queue`), what
one transaction does (:mod:`~engine.drivers.transaction_runner`), the retry and offline
rules (:mod:`~engine.drivers.bus_policy`), the claims (:mod:`~engine.drivers.device_table`), the
statistics (:mod:`~engine.drivers.device_stats`) and the drivers' handles
(:mod:`~engine.drivers.device_handle`).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from concurrent.futures import Future
from typing import TypeVar

from engine.clock import Clock
from engine.drivers.bus_errors import (
    AddressConflictError,
    BusClosedError,
    DeviceOfflineError,
    TransactionFailedError,
)
from engine.drivers.bus_policy import RETRYABLE_ERRNOS, BusPolicy, Priority
from engine.drivers.device_handle import DeviceHandle
from engine.drivers.device_stats import DeviceStats, percentile
from engine.drivers.job_queue import Job, JobQueue, fail_future
from engine.drivers.transaction_runner import TransactionRunner
from engine.errors import DeviceError

__all__ = [
    "RETRYABLE_ERRNOS",
    "AddressConflictError",
    "BusClosedError",
    "BusManager",
    "BusPolicy",
    "DeviceHandle",
    "DeviceOfflineError",
    "DeviceStats",
    "Priority",
    "TransactionFailedError",
    "percentile",
]

_log = logging.getLogger(__name__)

BusT = TypeVar("BusT")
T = TypeVar("T")

# How long (clock seconds) an idle worker waits before it looks again on its own; the
# doorbell wakes it at once whenever there is something to do.
_IDLE_WAIT_S = 60.0


class BusManager(TransactionRunner[BusT]):
    """The one owner of a bus: transactions in priority order, retries, offline devices.

    ``bus`` is the bus object transactions run against; the manager never closes it (it did
    not open it). ``name`` names the bus in messages (``"1"`` for ``/dev/i2c-1``,
    ``"/dev/ttyACM0"``) and ``kind`` says what it is (``"I2C"``, ``"SPI"``, ``"serial"``).

    Options (keyword-only):

    - ``threaded``: run transactions on a worker thread (default) or in the caller's thread.
    - ``on_status(device, ok)``: called when a device is claimed (``ok=True``) and whenever it
      goes offline or comes back, from the thread that ran the transaction or probe (the
      worker, or a :meth:`call` on an idle bus). Keep it short (stage a blackboard write);
      exceptions from it are logged, not raised.
    - ``retries``: extra attempts after a retryable error (``retry_errnos``), each after a
      backoff of ``backoff_s * 2**n`` seconds (n = 0, 1, ...) capped at ``max_backoff_s``,
      slept on ``clock``; ``offline_after`` consecutive failed transactions mark a device
      offline, re-probed every ``probe_interval_s`` seconds (see :class:`BusPolicy`).
    - ``latency_window``: how many recent transactions the latency percentiles cover.
    """

    def __init__(
        self,
        bus: BusT,
        *,
        name: str,
        clock: Clock,
        kind: str = "I2C",
        threaded: bool = True,
        on_status: Callable[[str, bool], None] | None = None,
        retries: int = 2,
        backoff_s: float = 0.001,
        max_backoff_s: float = 0.05,
        offline_after: int = 3,
        probe_interval_s: float = 2.0,
        retry_errnos: Iterable[int] = RETRYABLE_ERRNOS,
        latency_window: int = 1024,
    ) -> None:
        super().__init__(
            bus,
            name=name,
            kind=kind,
            clock=clock,
            on_status=on_status,
            latency_window=latency_window,
            policy=BusPolicy(
                retries=retries,
                backoff_s=backoff_s,
                max_backoff_s=max_backoff_s,
                offline_after=offline_after,
                probe_interval_s=probe_interval_s,
                retry_errnos=frozenset(retry_errnos),
            ),
        )
        self._threaded = threaded
        self._queue = JobQueue()
        self._closed = False
        # Threaded: the bus token, held while a transaction or probe runs (on the worker, or
        # in the thread of a call() that found the bus idle). Not threaded: a plain lock.
        self._busy = False
        self._bus_lock = threading.Lock()
        # Wakes the worker; an event of the clock, so a virtual clock drives the worker too.
        self._doorbell = clock.event()
        self._worker_asleep = False
        self._worker: threading.Thread | None = None
        if threaded:
            self._worker = threading.Thread(
                target=self._work, name=f"bus-{kind}-{name}", daemon=True
            )
            self._worker.start()

    # -- what it is ----------------------------------------------------------------------
    @property
    def threaded(self) -> bool:
        return self._threaded

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def pending(self) -> int:
        """Transactions queued and not yet started."""
        with self._lock:
            return len(self._queue)

    def __repr__(self) -> str:
        mode = "threaded" if self._threaded else "inline"
        return f"<BusManager {self.place(None)} {mode}, {len(self._table.records)} devices>"

    # -- claims --------------------------------------------------------------------------
    def claim(
        self,
        device: str,
        address: int | None = None,
        *,
        probe: Callable[[BusT], object] | None = None,
    ) -> DeviceHandle[BusT]:
        """Register ``device`` at ``address`` (``None``: the whole bus, as a serial port).

        ``probe(bus)`` re-checks an offline device (read its identity register; raise when
        it does not answer as it should). Without one, the first transaction due after the
        probe interval is let through as the probe. Raises
        :class:`~engine.drivers.bus_errors.AddressConflictError` naming the holder when the
        address (or the device name) is taken.
        """
        with self._lock:
            self._table.add(device, address, probe)
        self._notify(device, True)
        return DeviceHandle(self, device, address)

    # -- transactions --------------------------------------------------------------------
    def submit(
        self,
        device: str,
        fn: Callable[[BusT], T],
        *,
        priority: Priority = Priority.POLL,
    ) -> Future[T]:
        """Run ``fn(bus)`` for ``device``; the future holds its result or its error.

        Bus errors arrive as :class:`~engine.errors.DeviceError` (retries spent, device
        offline, bus closed); any other exception from ``fn`` (a driver bug) arrives as it
        was raised, without a retry. Threaded, this never waits for the bus; not threaded,
        ``fn`` has run when this returns.
        """
        job = self._job(device, fn, priority)
        if self._threaded:
            self._dispatch(job, may_run_here=False)
        else:
            self._run_inline(job)
        return job.future

    def call(
        self,
        device: str,
        fn: Callable[[BusT], T],
        *,
        priority: Priority = Priority.REQUEST,
        timeout_s: float | None = None,
    ) -> T:
        """Run ``fn(bus)`` for ``device`` and wait for its result (at most ``timeout_s`` s).

        For callers that wait anyway (a driver's setup, a polling thread). When the bus is
        idle (nothing queued or running, no device offline), ``fn`` runs in the calling
        thread, which saves the hand-off to the worker and back; otherwise it waits its turn
        like :meth:`submit`. Raises what the future would hold; on ``TimeoutError`` the
        transaction stays queued and still runs.
        """
        job = self._job(device, fn, priority)
        if self._threaded:
            self._dispatch(job, may_run_here=True)
        else:
            self._run_inline(job)
        result: T = job.future.result(timeout_s)
        return result

    def run_due_probes(self) -> None:
        """Re-probe offline devices whose probe is due (the worker does this on its own).

        For ``threaded=False``: transactions also re-probe first, but a device that only
        answers requests is re-probed only when someone calls this (the engine's loop).
        """
        if self._threaded:
            self._doorbell.set()
            return
        with self._bus_lock:
            self._run_due_probes()

    # -- closing -------------------------------------------------------------------------
    def close(self, *, timeout_s: float = 2.0) -> None:
        """Stop the worker and fail every queued transaction with a BusClosedError.

        A transaction already running finishes first (the worker is given ``timeout_s``
        real seconds). The bus object is left open: the manager did not open it.
        """
        with self._lock:
            if self._closed:
                return
            self._closed = True
            pending = self._queue.drain()
        self._doorbell.set()
        for job in pending:
            fail_future(job.future, self._closed_error(job.device, queued=True))
        worker = self._worker
        if worker is not None and worker is not threading.current_thread():
            worker.join(timeout_s)

    def __enter__(self) -> BusManager[BusT]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- inside ----------------------------------------------------------------------------
    def _closed_error(self, device: str, *, queued: bool = False) -> BusClosedError:
        if queued:
            text = f"{self.place(None)} was closed before {device}'s transaction ran"
        else:
            text = f"{self.place(None)} is closed; {device}'s transaction was not run"
        return BusClosedError(text, device=device)

    def _job(self, device: str, fn: Callable[[BusT], T], priority: Priority) -> Job:
        if priority.__class__ is not Priority:
            priority = Priority(priority)
        if self._active_thread == threading.get_ident():
            raise RuntimeError(
                f"{device}: a transaction on {self.place(None)} submitted another one to the "
                "same bus; it would wait for itself. Do all of it in one transaction."
            )
        return Job(device, fn, Future(), priority)

    def _dispatch(self, job: Job, *, may_run_here: bool) -> None:
        """Threaded: queue ``job`` for the worker, or run it in this thread when allowed and
        the bus is idle."""
        ring = run_here = False
        with self._lock:
            state = self._state(job.device)
            if self._closed:
                refusal: DeviceError | None = self._closed_error(job.device)
            else:
                refusal = self._refusal(state, job.priority)
            if refusal is None:
                if may_run_here and not (self._busy or self._queue or self._table.offline):
                    self._busy = run_here = True
                else:
                    self._queue.push(job)
                    ring, self._worker_asleep = self._worker_asleep, False
        if refusal is not None:
            fail_future(job.future, refusal)
        elif run_here:
            try:
                self._execute(job)
            finally:
                self._release_bus()
        elif ring:
            self._doorbell.set()

    def _release_bus(self) -> None:
        """Give the bus token back; wake the worker if something waits for the bus."""
        with self._lock:
            self._busy = False
            ring = self._worker_asleep and bool(self._queue or self._table.offline)
            if ring:
                self._worker_asleep = False
        if ring:
            self._doorbell.set()

    def _run_inline(self, job: Job) -> None:
        """Not threaded: due probes, then ``job``, in this thread, one caller at a time."""
        with self._bus_lock:
            with self._lock:
                self._state(job.device)  # unknown names fail at once, in the caller
                closed = self._closed
            if not closed:
                if self._table.offline:
                    self._run_due_probes()
                self._execute(job)
        if closed:
            fail_future(job.future, self._closed_error(job.device))

    def _work(self) -> None:
        """The worker: probes that are due, then the most urgent transaction, until closed.

        It waits on the clock (:meth:`~engine.clock.Clock.wait`) for the doorbell or the next
        re-probe, so a virtual clock drives it as it drives the rest of the engine.
        """
        while True:
            job: Job | None = None
            wait_s = _IDLE_WAIT_S
            with self._lock:
                self._worker_asleep = False
                if self._closed:
                    return
                run = False
                if not self._busy:  # else a call() holds the bus and rings when it is done
                    if self._queue:
                        job = self._queue.pop()
                        run = True
                    elif self._table.offline:
                        due_s = self._table.next_probe_due()
                        if due_s is not None:
                            wait_s = due_s - self._clock.now()
                            run = wait_s <= 0
                if run:
                    self._busy = True
                else:
                    self._worker_asleep = True
                probes_pending = self._table.offline > 0
            if not run:
                self._clock.wait(self._doorbell, wait_s)
                self._doorbell.clear()  # what it rang for is looked at next, under the lock
                continue
            try:
                if probes_pending:
                    self._run_due_probes()
                if job is not None:
                    self._execute(job)
            except Exception as exc:  # a bug here must not kill the bus
                _log.exception("%s: the bus worker failed", self.place(None))
                if job is not None:
                    fail_future(job.future, exc)
            finally:
                self._release_bus()
