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
hand-off to the worker and back (tens of microseconds, most of the manager's cost).
"""

from __future__ import annotations

import contextlib
import errno
import heapq
import itertools
import logging
import math
import queue
import threading
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future, InvalidStateError
from dataclasses import dataclass
from enum import IntEnum
from typing import Any, Generic, TypeVar

from engine.clock import Clock, stopwatch
from engine.drivers.bus_errors import (
    AddressConflictError,
    BusClosedError,
    DeviceOfflineError,
    TransactionFailedError,
    describe_exception,
    errno_in_words,
)
from engine.errors import DeviceError

__all__ = [
    "RETRYABLE_ERRNOS",
    "AddressConflictError",
    "BusClosedError",
    "BusManager",
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

#: Errors a second attempt can fix: the chip did not acknowledge (EREMOTEIO, ENXIO), the
#: adapter reported an I/O error or a timeout (a chip stretching the clock, a glitch), or
#: the adapter was busy (EAGAIN, also reported as arbitration loss on multi-master buses).
RETRYABLE_ERRNOS: frozenset[int] = frozenset(
    {errno.EREMOTEIO, errno.ENXIO, errno.EIO, errno.ETIMEDOUT, errno.EAGAIN}
)

# A worker with only offline devices to re-probe re-reads the clock at least this often
# (real seconds), so it also notices a clock that was moved by someone else.
_MAX_IDLE_WAIT_S = 0.5


class Priority(IntEnum):
    """Which transaction runs first; lower values first, FIFO within a value."""

    REQUEST = 0
    """Someone is waiting for the answer (an on-request read from a tree, a driver's setup)."""
    POLL = 1
    """Routine polling; refused without touching the bus while the device is offline."""


def percentile(sorted_values: Sequence[float], fraction: float) -> float:
    """The nearest-rank percentile of ``sorted_values`` (ascending); ``0.0`` when empty.

    ``fraction`` is in 0..1 (``0.99`` for p99).
    """
    if not 0.0 <= fraction <= 1.0:
        raise ValueError(f"percentile fraction must be within 0..1, got {fraction}")
    if not sorted_values:
        return 0.0
    rank = max(1, math.ceil(fraction * len(sorted_values)))
    return float(sorted_values[rank - 1])


@dataclass(frozen=True, slots=True)
class DeviceStats:
    """What one device's transactions did, as a plain snapshot for the debug tools.

    Latencies are the time a transaction held the bus, retries and backoff included,
    over the most recent transactions (the manager's ``latency_window``), in microseconds.
    """

    device: str
    bus: str
    address: int | None
    online: bool
    transactions: int
    """Transactions that reached the bus (probes and refused polls not counted)."""
    errors: int
    """Transactions that failed, after their retries."""
    retries: int
    """Extra attempts made after a retryable bus error."""
    refused: int
    """Polls answered "offline" without touching the bus."""
    probes: int
    """Re-probes made while the device was offline."""
    consecutive_failures: int
    latency_p50_us: float
    latency_p99_us: float
    latency_max_us: float
    last_error: str | None


class _Device:
    """A claim and its running state; guarded by the manager's lock."""

    __slots__ = (
        "address",
        "consecutive_failures",
        "errors",
        "last_error",
        "latencies_us",
        "latency_max_us",
        "name",
        "next_probe_s",
        "online",
        "probe",
        "probes",
        "refused",
        "retries",
        "transactions",
    )

    def __init__(
        self,
        name: str,
        address: int | None,
        probe: Callable[[Any], object] | None,
        latency_window: int,
    ) -> None:
        self.name = name
        self.address = address
        self.probe = probe
        self.online = True
        self.consecutive_failures = 0
        self.next_probe_s = 0.0
        self.transactions = 0
        self.errors = 0
        self.retries = 0
        self.refused = 0
        self.probes = 0
        self.latencies_us: deque[float] = deque(maxlen=latency_window)
        self.latency_max_us = 0.0
        self.last_error: str | None = None


@dataclass(slots=True)
class _Job:
    device: str
    fn: Callable[[Any], Any]
    future: Future[Any]
    priority: Priority


class BusManager(Generic[BusT]):
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
      slept on ``clock``.
    - ``offline_after``: consecutive failed transactions that mark a device offline.
    - ``probe_interval_s``: seconds between re-probes of an offline device.
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
        if retries < 0:
            raise ValueError(f"retries must be 0 or more, got {retries}")
        if backoff_s < 0 or max_backoff_s < 0:
            raise ValueError(
                f"backoff must not be negative, got backoff_s={backoff_s}, "
                f"max_backoff_s={max_backoff_s}"
            )
        if offline_after < 1:
            raise ValueError(f"offline_after must be 1 or more, got {offline_after}")
        if probe_interval_s <= 0:
            raise ValueError(f"probe_interval_s must be positive, got {probe_interval_s}")
        if latency_window < 1:
            raise ValueError(f"latency_window must be 1 or more, got {latency_window}")
        self._bus = bus
        self._name = name
        self._kind = kind
        self._clock = clock
        self._threaded = threaded
        self._on_status = on_status
        self._retries = retries
        self._backoff_s = backoff_s
        self._max_backoff_s = max_backoff_s
        self._offline_after = offline_after
        self._probe_interval_s = probe_interval_s
        self._retry_errnos = frozenset(retry_errnos)
        self._latency_window = latency_window

        self._lock = threading.Lock()  # guards claims, device state, the queue and the flags
        self._devices: dict[str, _Device] = {}
        self._holders: dict[int | None, str] = {}
        self._offline = 0
        self._queue: list[tuple[int, int, _Job]] = []
        self._sequence = itertools.count()
        self._closed = False
        # The thread running a transaction or probe right now; a transaction that submits
        # another one to its own bus would wait for itself.
        self._active_thread: int | None = None
        # Threaded: the bus token, held while a transaction or probe runs (on the worker, or
        # in the thread of a call() that found the bus idle). Not threaded: a plain lock.
        self._busy = False
        self._bus_lock = threading.Lock()
        # Wakes the worker: cheaper than a Condition (the hand-off is most of the overhead).
        self._doorbell: queue.SimpleQueue[None] = queue.SimpleQueue()
        self._worker_asleep = False
        self._worker: threading.Thread | None = None
        if threaded:
            self._worker = threading.Thread(
                target=self._work, name=f"bus-{kind}-{name}", daemon=True
            )
            self._worker.start()

    # -- what it is ----------------------------------------------------------------------
    @property
    def name(self) -> str:
        """The bus's name in messages (``"1"`` for ``/dev/i2c-1``)."""
        return self._name

    @property
    def kind(self) -> str:
        """What the bus is (``"I2C"``, ``"SPI"``, ``"serial"``)."""
        return self._kind

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

    def place(self, address: int | None) -> str:
        """``"I2C 0x29 on bus 1"``, or ``"I2C bus 1"`` for a claim of the whole bus."""
        if address is None:
            return f"{self._kind} bus {self._name}"
        return f"{self._kind} 0x{address:02X} on bus {self._name}"

    def __repr__(self) -> str:
        mode = "threaded" if self._threaded else "inline"
        return f"<BusManager {self.place(None)} {mode}, {len(self._devices)} devices>"

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
        if not isinstance(device, str) or not device:
            raise ValueError(f"a device needs a non-empty name, got {device!r}")
        if address is not None and (
            isinstance(address, bool) or not isinstance(address, int) or address < 0
        ):
            raise ValueError(f"{device}: address must be a non-negative int, got {address!r}")
        with self._lock:
            if device in self._devices:
                held = self._devices[device].address
                raise AddressConflictError(
                    f"device name {device!r} is already claimed at {self.place(held)}; "
                    "give each device its own name"
                )
            holder = self._holders.get(None) or self._holders.get(address)
            if holder is None and address is None and self._holders:
                holder = next(iter(self._holders.values()))
            if holder is not None:
                whole_bus = address is None or None in self._holders
                where = self.place(None if whole_bus else address)
                raise AddressConflictError(f"{where} is already used by {holder}")
            self._devices[device] = _Device(device, address, probe, self._latency_window)
            self._holders[address] = device
        self._notify(device, True)
        return DeviceHandle(self, device, address)

    def release(self, device: str) -> None:
        """Give up ``device``'s claim; its queued transactions fail when their turn comes."""
        with self._lock:
            state = self._devices.pop(device, None)
            if state is None:
                return
            del self._holders[state.address]
            if not state.online:
                self._offline -= 1

    @property
    def devices(self) -> dict[str, int | None]:
        """Claimed device names and their addresses."""
        with self._lock:
            return {name: state.address for name, state in self._devices.items()}

    def holder(self, address: int | None) -> str | None:
        """The name of the device that claimed ``address``, if any."""
        with self._lock:
            return self._holders.get(address)

    def is_online(self, device: str) -> bool:
        with self._lock:
            return self._state(device).online

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
        return job.future.result(timeout_s)

    def run_due_probes(self) -> None:
        """Re-probe offline devices whose probe is due (the worker does this on its own).

        For ``threaded=False``: transactions also re-probe first, but a device that only
        answers requests is re-probed only when someone calls this (the engine's loop).
        """
        if self._threaded:
            self._doorbell.put(None)
            return
        with self._bus_lock:
            self._run_due_probes()

    # -- statistics ----------------------------------------------------------------------
    def stats(self) -> dict[str, DeviceStats]:
        """A snapshot of every claimed device's statistics, by device name."""
        with self._lock:
            copies = [
                (
                    state,
                    state.online,
                    state.transactions,
                    state.errors,
                    state.retries,
                    state.refused,
                    state.probes,
                    state.consecutive_failures,
                    sorted(state.latencies_us),
                    state.latency_max_us,
                    state.last_error,
                )
                for state in self._devices.values()
            ]
        snapshot: dict[str, DeviceStats] = {}
        for state, online, txn, err, ret, ref, prb, cons, lat, lat_max, last in copies:
            snapshot[state.name] = DeviceStats(
                device=state.name,
                bus=self._name,
                address=state.address,
                online=online,
                transactions=txn,
                errors=err,
                retries=ret,
                refused=ref,
                probes=prb,
                consecutive_failures=cons,
                latency_p50_us=percentile(lat, 0.50),
                latency_p99_us=percentile(lat, 0.99),
                latency_max_us=lat_max,
                last_error=last,
            )
        return snapshot

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
            pending = [job for _, _, job in sorted(self._queue, key=lambda e: e[:2])]
            self._queue.clear()
        self._doorbell.put(None)
        for job in pending:
            _fail(job.future, self._closed_error(job.device, queued=True))
        worker = self._worker
        if worker is not None and worker is not threading.current_thread():
            worker.join(timeout_s)

    def __enter__(self) -> BusManager[BusT]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- inside ----------------------------------------------------------------------------
    def _state(self, device: str) -> _Device:
        """The device's state (lock held); unknown names are a programming error."""
        state = self._devices.get(device)
        if state is None:
            raise ValueError(
                f"device {device!r} has not claimed an address on {self.place(None)}; "
                "call claim(name, address) first"
            )
        return state

    def _job(self, device: str, fn: Callable[[BusT], T], priority: Priority) -> _Job:
        if priority.__class__ is not Priority:
            priority = Priority(priority)
        if self._active_thread == threading.get_ident():
            raise RuntimeError(
                f"{device}: a transaction on {self.place(None)} submitted another one to the "
                "same bus; it would wait for itself. Do all of it in one transaction."
            )
        return _Job(device, fn, Future(), priority)

    def _dispatch(self, job: _Job, *, may_run_here: bool) -> None:
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
                if may_run_here and not (self._busy or self._queue or self._offline):
                    self._busy = run_here = True
                else:
                    heapq.heappush(self._queue, (job.priority, next(self._sequence), job))
                    ring, self._worker_asleep = self._worker_asleep, False
        if refusal is not None:
            _fail(job.future, refusal)
        elif run_here:
            try:
                self._execute(job)
            finally:
                self._release_bus()
        elif ring:
            self._doorbell.put(None)

    def _release_bus(self) -> None:
        """Give the bus token back; wake the worker if something waits for the bus."""
        with self._lock:
            self._busy = False
            ring = self._worker_asleep and bool(self._queue or self._offline)
            if ring:
                self._worker_asleep = False
        if ring:
            self._doorbell.put(None)

    def _run_inline(self, job: _Job) -> None:
        """Not threaded: due probes, then ``job``, in this thread, one caller at a time."""
        with self._bus_lock:
            with self._lock:
                self._state(job.device)  # unknown names fail at once, in the caller
                closed = self._closed
            if not closed:
                if self._offline:
                    self._run_due_probes()
                self._execute(job)
        if closed:
            _fail(job.future, self._closed_error(job.device))

    def _refusal(self, state: _Device, priority: Priority) -> DeviceError | None:
        """Why a transaction must not reach the bus now (lock held), or None."""
        if state.online or priority is Priority.REQUEST:
            return None
        now_s = self._clock.now()
        if now_s >= state.next_probe_s:
            return None
        state.refused += 1
        return DeviceOfflineError(
            f"{state.name} ({self.place(state.address)}) is offline after "
            f"{state.consecutive_failures} failed transactions (last: {state.last_error}); "
            f"next re-probe in {state.next_probe_s - now_s:.1f} s",
            device=state.name,
        )

    def _closed_error(self, device: str, *, queued: bool = False) -> BusClosedError:
        if queued:
            text = f"{self.place(None)} was closed before {device}'s transaction ran"
        else:
            text = f"{self.place(None)} is closed; {device}'s transaction was not run"
        return BusClosedError(text, device=device)

    def _backoff(self, attempt: int) -> float:
        return min(self._backoff_s * 2 ** (attempt - 1), self._max_backoff_s)

    def _retryable(self, exc: OSError) -> bool:
        return not isinstance(exc, DeviceError) and exc.errno in self._retry_errnos

    def _execute(self, job: _Job) -> None:
        """Run one transaction with its retries, in the thread that owns the bus now."""
        if not job.future.set_running_or_notify_cancel():
            return  # cancelled by its caller while queued
        with self._lock:
            state = self._devices.get(job.device)
            if state is None:
                error: BaseException | None = DeviceError(
                    f"{job.device} released its claim on {self.place(None)} before its "
                    "transaction ran"
                )
            else:
                error = self._refusal(state, job.priority)
                attempts = self._retries + 1
                if error is None and not state.online:
                    attempts = 1  # one try, no retries: the device is offline
                    if state.probe is None:  # this transaction is the probe
                        state.probes += 1
                        state.next_probe_s = self._clock.now() + self._probe_interval_s
        if state is None or error is not None:
            _fail(job.future, error)  # type: ignore[arg-type]  # set whenever state is None
            return

        self._active_thread = threading.get_ident()
        started = stopwatch()
        attempt = 0
        bus_failure = False
        try:
            while True:
                attempt += 1
                try:
                    result = job.fn(self._bus)
                except OSError as exc:
                    if attempt < attempts and self._retryable(exc):
                        with self._lock:
                            state.retries += 1
                        self._clock.sleep(self._backoff(attempt))
                        continue
                    error, bus_failure = exc, True
                except Exception as exc:
                    error = exc
                break
        finally:
            self._active_thread = None
        latency_us = (stopwatch() - started) * 1e6

        went_offline = self._settle(state, latency_us, error, bus_failure)
        if went_offline is not None:
            self._notify(state.name, not went_offline)
        if error is None:
            job.future.set_result(result)
            return
        if bus_failure and not isinstance(error, DeviceError):
            error = self._failure(state, error, attempt, went_offline is True)
        _fail(job.future, error)

    def _settle(
        self, state: _Device, latency_us: float, error: BaseException | None, bus_failure: bool
    ) -> bool | None:
        """Record a finished transaction; True if it took the device offline, False if it
        brought it back, None if the status did not change."""
        with self._lock:
            state.transactions += 1
            state.latencies_us.append(latency_us)
            state.latency_max_us = max(state.latency_max_us, latency_us)
            if error is None:
                state.consecutive_failures = 0
                if not state.online:
                    self._set_online(state, True)
                    return False
                return None
            state.errors += 1
            state.last_error = describe_exception(error)
            if not bus_failure:
                return None  # a driver bug says nothing about the device
            state.consecutive_failures += 1
            if state.online and state.consecutive_failures >= self._offline_after:
                self._set_online(state, False)
                return True
            return None

    def _set_online(self, state: _Device, online: bool) -> None:
        """Flip a device's status (lock held)."""
        state.online = online
        if online:
            state.consecutive_failures = 0
        else:
            state.next_probe_s = self._clock.now() + self._probe_interval_s
        if self._devices.get(state.name) is state:
            self._offline += -1 if online else 1

    def _failure(
        self, state: _Device, exc: OSError, attempts: int, went_offline: bool
    ) -> TransactionFailedError:
        code = exc.errno if isinstance(exc.errno, int) else None
        words = errno_in_words(code) if code is not None else describe_exception(exc)
        tries = "1 attempt" if attempts == 1 else f"{attempts} attempts"
        text = f"{state.name} ({self.place(state.address)}): {words} after {tries}"
        if went_offline:
            text += (
                f"; {state.name} is now offline and will be re-probed every "
                f"{self._probe_interval_s:g} s"
            )
        failure = TransactionFailedError(text, device=state.name, code=code, attempts=attempts)
        failure.__cause__ = exc
        return failure

    def _run_due_probes(self) -> None:
        """Re-probe every offline device whose probe is due (in the bus-owning thread)."""
        now_s = self._clock.now()
        with self._lock:
            due = [
                state
                for state in self._devices.values()
                if not state.online and state.probe is not None and now_s >= state.next_probe_s
            ]
        for state in due:
            self._probe(state)

    def _probe(self, state: _Device) -> None:
        probe = state.probe
        assert probe is not None
        self._active_thread = threading.get_ident()
        try:
            probe(self._bus)
        except Exception as exc:
            with self._lock:
                state.probes += 1
                state.last_error = describe_exception(exc)
                state.next_probe_s = self._clock.now() + self._probe_interval_s
            return
        finally:
            self._active_thread = None
        with self._lock:
            state.probes += 1
            changed = not state.online
            if changed:
                self._set_online(state, True)
        if changed:
            self._notify(state.name, True)

    def _next_probe_due(self) -> float | None:
        """When the earliest re-probe is due (lock held), or None when none is pending."""
        if not self._offline:
            return None
        dues = [
            state.next_probe_s
            for state in self._devices.values()
            if not state.online and state.probe is not None
        ]
        return min(dues) if dues else None

    def _work(self) -> None:
        """The worker: probes that are due, then the most urgent transaction, until closed."""
        while True:
            job: _Job | None = None
            wait_s: float | None = None
            with self._lock:
                self._worker_asleep = False
                if self._closed:
                    return
                run = False
                if not self._busy:  # else a call() holds the bus and rings when it is done
                    if self._queue:
                        job = heapq.heappop(self._queue)[2]
                        run = True
                    elif self._offline:
                        due_s = self._next_probe_due()
                        if due_s is not None:
                            wait_s = min(due_s - self._clock.now(), _MAX_IDLE_WAIT_S)
                            run = wait_s <= 0
                if run:
                    self._busy = True
                else:
                    self._worker_asleep = True
                probes_pending = self._offline > 0
            if not run:
                with contextlib.suppress(queue.Empty):
                    self._doorbell.get(timeout=wait_s)
                continue
            try:
                if probes_pending:
                    self._run_due_probes()
                if job is not None:
                    self._execute(job)
            except Exception as exc:  # a bug here must not kill the bus
                _log.exception("%s: the bus worker failed", self.place(None))
                if job is not None:
                    _fail(job.future, exc)
            finally:
                self._release_bus()

    def _notify(self, device: str, ok: bool) -> None:
        if self._on_status is None:
            return
        try:
            self._on_status(device, ok)
        except Exception:
            _log.exception("on_status(%r, %r) raised; the bus carries on", device, ok)


def _fail(future: Future[Any], error: BaseException) -> None:
    """Fail ``future`` unless its caller cancelled it meanwhile."""
    with contextlib.suppress(InvalidStateError):
        future.set_exception(error)


class DeviceHandle(Generic[BusT]):
    """A driver's claim on a bus: submit transactions under its own name.

    ``address`` is the claimed address, for the driver's own ``bus.read_byte_data(address,
    ...)`` calls.
    """

    __slots__ = ("_address", "_manager", "_name")

    def __init__(self, manager: BusManager[BusT], name: str, address: int | None) -> None:
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
    def manager(self) -> BusManager[BusT]:
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

    def release(self) -> None:
        self._manager.release(self._name)

    def __repr__(self) -> str:
        return f"<DeviceHandle {self._name} at {self._manager.place(self._address)}>"
