"""What one transaction does on a bus: retries, its device's status, its statistics.

:class:`TransactionRunner` is the half of a :class:`~engine.drivers.bus_manager.BusManager`
that runs a transaction (or a re-probe) once it has the bus: it retries what its
:class:`~engine.drivers.bus_policy.BusPolicy` says a second try can fix, backing off on
the injected clock, settles the device's status (offline after repeated failures, back
after a good answer) and counts it all in the device's
:class:`~engine.drivers.device_stats.DeviceRecord`. *When* a transaction runs (the queue,
the worker thread, or at once in the caller's thread) is the manager's business.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Generic, TypeVar

from engine.clock import Clock, stopwatch
from engine.drivers.bus_policy import BusPolicy, Priority
from engine.drivers.device_stats import DeviceRecord, DeviceStats, snapshot
from engine.drivers.device_table import DeviceTable
from engine.drivers.job_queue import Job, fail_future
from engine.errors import DeviceError

__all__ = ["TransactionRunner"]

# The manager's logger: its messages keep the name they had before the split.
_log = logging.getLogger("engine.drivers.bus_manager")

BusT = TypeVar("BusT")


class TransactionRunner(Generic[BusT]):
    """Runs transactions and re-probes on ``bus`` for the devices of its table.

    ``name`` names the bus in messages (``"1"`` for ``/dev/i2c-1``), ``kind`` says what it
    is (``"I2C"``, ``"SPI"``, ``"serial"``); ``on_status(device, ok)`` hears a device go
    offline or come back. Every method that touches the table holds ``_lock``.
    """

    def __init__(
        self,
        bus: BusT,
        *,
        name: str,
        kind: str,
        clock: Clock,
        policy: BusPolicy,
        on_status: Callable[[str, bool], None] | None,
        latency_window: int,
    ) -> None:
        if latency_window < 1:
            raise ValueError(f"latency_window must be 1 or more, got {latency_window}")
        self._bus = bus
        self._name = name
        self._kind = kind
        self._clock = clock
        self._policy = policy
        self._on_status = on_status
        self._lock = threading.Lock()  # guards the table, the records and the owner's queue
        self._table = DeviceTable(self.place, latency_window=latency_window)
        # The thread running a transaction or probe right now; a transaction that submits
        # another one to its own bus would wait for itself.
        self._active_thread: int | None = None

    @property
    def name(self) -> str:
        """The bus's name in messages (``"1"`` for ``/dev/i2c-1``)."""
        return self._name

    @property
    def kind(self) -> str:
        """What the bus is (``"I2C"``, ``"SPI"``, ``"serial"``)."""
        return self._kind

    @property
    def policy(self) -> BusPolicy:
        """The retry and offline rules of this bus."""
        return self._policy

    def place(self, address: int | None) -> str:
        """``"I2C 0x29 on bus 1"``, or ``"I2C bus 1"`` for a claim of the whole bus."""
        if address is None:
            return f"{self._kind} bus {self._name}"
        return f"{self._kind} 0x{address:02X} on bus {self._name}"

    # -- claims --------------------------------------------------------------------------
    def release(self, device: str) -> None:
        """Give up ``device``'s claim; its queued transactions fail when their turn comes."""
        with self._lock:
            self._table.remove(device)

    @property
    def devices(self) -> dict[str, int | None]:
        """Claimed device names and their addresses."""
        with self._lock:
            return {name: record.address for name, record in self._table.records.items()}

    def holder(self, address: int | None) -> str | None:
        """The name of the device that claimed ``address``, if any."""
        with self._lock:
            return self._table.holders.get(address)

    def is_online(self, device: str) -> bool:
        with self._lock:
            return self._state(device).online

    # -- statistics ----------------------------------------------------------------------
    def stats(self) -> dict[str, DeviceStats]:
        """A snapshot of every claimed device's statistics, by device name."""
        with self._lock:
            frozen = [record.frozen() for record in self._table.records.values()]
        return {counters[0]: snapshot(self._name, counters) for counters in frozen}

    def note_implausible(self, device: str, error: BaseException) -> None:
        """Count a reading ``device``'s driver refused after its transactions had succeeded
        (an :class:`~engine.drivers.device_errors.ImplausibleReadingError` found by a poller that
        reads register by register), as a transaction's own would be counted."""
        with self._lock:
            self._policy.count_error(self._state(device), error)

    def _state(self, device: str) -> DeviceRecord:
        """The device's record (lock held); unknown names are a programming error."""
        return self._table.get(device)

    def _refusal(self, state: DeviceRecord, priority: Priority) -> DeviceError | None:
        """Why a transaction must not reach the bus now (lock held), or None."""
        return self._policy.refusal(state, priority, self._clock.now(), self.place(state.address))

    def _execute(self, job: Job) -> None:
        """Run one transaction with its retries, in the thread that owns the bus now."""
        if not job.future.set_running_or_notify_cancel():
            return  # cancelled by its caller while queued
        policy = self._policy
        with self._lock:
            state = self._table.records.get(job.device)
            if state is None:
                error: BaseException | None = DeviceError(
                    f"{job.device} released its claim on {self.place(None)} before its "
                    "transaction ran"
                )
            else:
                error = self._refusal(state, job.priority)
                if error is None:
                    attempts = policy.attempts(state, self._clock.now())
        if state is None or error is not None:
            fail_future(job.future, error)  # type: ignore[arg-type]  # set whenever state is None
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
                    if attempt < attempts and policy.retryable(exc):
                        with self._lock:
                            state.retries += 1
                        self._clock.sleep(policy.backoff_for(attempt))
                        continue
                    error, bus_failure = exc, True
                except Exception as exc:
                    error = exc
                break
        finally:
            self._active_thread = None
        latency_us = (stopwatch() - started) * 1e6

        with self._lock:
            state.add_latency(latency_us)
            went_offline = policy.settle(state, self._clock.now(), error, bus_failure)
            if went_offline is not None:
                self._table.flipped(state)
        if went_offline is not None:
            self._notify(state.name, not went_offline)
        if error is None:
            job.future.set_result(result)
            return
        if bus_failure and not isinstance(error, DeviceError):
            assert isinstance(error, OSError)
            error = policy.failure(
                state, self.place(state.address), error, attempt, went_offline is True
            )
        fail_future(job.future, error)

    def _run_due_probes(self) -> None:
        """Re-probe every offline device whose probe is due (in the bus-owning thread)."""
        now_s = self._clock.now()
        with self._lock:
            due = self._table.due_probes(now_s)
        for state in due:
            self._probe(state)

    def _probe(self, state: DeviceRecord) -> None:
        probe = state.probe
        assert probe is not None
        self._active_thread = threading.get_ident()
        error: BaseException | None = None
        try:
            probe(self._bus)
        except Exception as exc:
            error = exc
        finally:
            self._active_thread = None
        with self._lock:
            back = self._policy.probed(state, self._clock.now(), error)
            if back:
                self._table.flipped(state)
        if back:
            self._notify(state.name, True)

    def _notify(self, device: str, ok: bool) -> None:
        if self._on_status is None:
            return
        try:
            self._on_status(device, ok)
        except Exception:
            _log.exception("on_status(%r, %r) raised; the bus carries on", device, ok)
