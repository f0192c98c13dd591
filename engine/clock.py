"""Clocks: the only place in the engine that reads time or sleeps.

Everything else receives a :class:`Clock` and asks it. ``RealClock`` follows the machine's
monotonic clock; ``VirtualClock`` only moves when told to, so a test can advance ten
seconds in a millisecond and a scenario can run as fast as the machine allows.
All times are in seconds.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
import time
from typing import Protocol


class Clock(Protocol):
    """A monotonic source of time in seconds, and a way to wait for it."""

    def now(self) -> float:
        """Seconds since an arbitrary origin; never goes backwards."""
        ...

    def sleep(self, seconds: float) -> None:
        """Wait ``seconds`` (no-op for zero or negative)."""
        ...

    def sleep_until(self, deadline_s: float, stop: ClockEvent | None = None) -> bool:
        """Wait until :meth:`now` reaches ``deadline_s`` (returns at once if it has), or
        until ``stop`` is set: returns True when it was (the scheduler's stop request)."""
        ...

    def event(self) -> ClockEvent:
        """A new flag that :meth:`wait` can wait for (a thread's stop request, say)."""
        ...

    def wait(self, event: ClockEvent, timeout_s: float) -> bool:
        """Wait until ``event`` is set or ``timeout_s`` of this clock's time has passed.

        Returns True when the event is set (at once if it already is): each worker waits
        for its own event, so stopping one never cuts short another's sleep.
        """
        ...

    async def wait_async(self, event: asyncio.Event, timeout_s: float) -> bool:
        """On an event loop: until ``event`` is set or ``timeout_s`` of this clock's time has
        passed, holding no thread (a web service's long-polls and streams). True when set."""
        ...


class ClockEvent:
    """A flag set by one thread and waited for by another on a clock's time.

    Made by :meth:`Clock.event`; setting it wakes a :meth:`Clock.wait` on it at once.
    """

    def __init__(self, condition: threading.Condition) -> None:
        self._condition = condition
        self._set = False

    def set(self) -> None:
        with self._condition:
            self._set = True
            self._condition.notify_all()

    def clear(self) -> None:
        with self._condition:
            self._set = False

    def is_set(self) -> bool:
        return self._set


class RealClock:
    """The machine's monotonic clock."""

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)

    def sleep_until(self, deadline_s: float, stop: ClockEvent | None = None) -> bool:
        if stop is not None:
            return self.wait(stop, deadline_s - time.monotonic())
        self.sleep(deadline_s - time.monotonic())
        return False

    def event(self) -> ClockEvent:
        return ClockEvent(threading.Condition())

    def wait(self, event: ClockEvent, timeout_s: float) -> bool:
        deadline = time.monotonic() + max(timeout_s, 0.0)
        with event._condition:
            while not event.is_set():
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                event._condition.wait(left)
        return True

    async def wait_async(self, event: asyncio.Event, timeout_s: float) -> bool:
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(event.wait(), max(timeout_s, 0.0))
        return event.is_set()


class EpochClock(RealClock):
    """Seconds since the Unix epoch (UTC): for times that are stored and shown as dates
    (the cloud service's ledger, a robot's last call). Not monotonic: the machine's time
    may be set back, so measure durations with :class:`RealClock`."""

    def now(self) -> float:
        return time.time()

    def sleep_until(self, deadline_s: float, stop: ClockEvent | None = None) -> bool:
        return super().sleep_until(time.monotonic() + (deadline_s - time.time()), stop)


class VirtualClock:
    """A clock that moves only when advanced; sleeping advances it.

    Used by tests and by ``vest run --fast``: ``sleep_until(t)`` jumps straight to ``t``.
    Thread-safe, so a worker thread may read it while the owner advances it.
    """

    def __init__(self, start_s: float = 0.0) -> None:
        self._now = start_s
        self._lock = threading.Condition()
        self._waiting = 0
        self._entered = 0
        self._async_waits: list[_AsyncWait] = []

    def now(self) -> float:
        return self._now

    def advance(self, seconds: float) -> None:
        """Move time forward by ``seconds`` (must not be negative)."""
        if seconds < 0:
            raise ValueError(f"a clock cannot go backwards: advance({seconds})")
        with self._lock:
            self._now += seconds
            self._wake_async_waits()
            self._lock.notify_all()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            self.advance(seconds)

    def sleep_until(self, deadline_s: float, stop: ClockEvent | None = None) -> bool:
        """Jump to ``deadline_s`` at once, unless ``stop`` is already set (True then)."""
        if stop is not None and stop.is_set():
            return True
        with self._lock:
            self._now = max(self._now, deadline_s)
            self._wake_async_waits()
            self._lock.notify_all()
        return False

    def event(self) -> ClockEvent:
        return ClockEvent(self._lock)

    def wait(self, event: ClockEvent, timeout_s: float) -> bool:
        """Block this thread until ``event`` is set or another thread advances the clock by
        ``timeout_s``: a virtual clock drives threaded code as it drives the scheduler."""
        if event._condition is not self._lock:
            raise ValueError("wait on an event made by this clock (clock.event())")
        with self._lock:
            deadline = self._now + max(timeout_s, 0.0)
            self._waiting += 1
            self._entered += 1
            self._lock.notify_all()
            try:
                while not event.is_set() and self._now < deadline:
                    self._lock.wait()
            finally:
                self._waiting -= 1
            return event.is_set()

    async def wait_async(self, event: asyncio.Event, timeout_s: float) -> bool:
        """Until ``event`` is set or another thread advances the clock by ``timeout_s``;
        counted as a waiter by :meth:`until_waiting`, as a thread in :meth:`wait` is."""
        wait = _AsyncWait(asyncio.get_running_loop())
        with self._lock:
            wait.deadline_s = self._now + max(timeout_s, 0.0)
            if event.is_set() or self._now >= wait.deadline_s:
                return event.is_set()
            self._async_waits.append(wait)
            self._waiting += 1
            self._entered += 1
            self._lock.notify_all()
        woken = asyncio.ensure_future(event.wait())
        timed_out = asyncio.ensure_future(wait.timed_out.wait())
        try:
            await asyncio.wait((woken, timed_out), return_when=asyncio.FIRST_COMPLETED)
        finally:
            woken.cancel()
            timed_out.cancel()
            with self._lock:
                self._async_waits.remove(wait)
                self._waiting -= 1
        return event.is_set()

    def _wake_async_waits(self) -> None:
        """(Holding the lock.) Ends the async waits whose time has come, on their loops."""
        for wait in self._async_waits:
            if self._now >= wait.deadline_s:
                with contextlib.suppress(RuntimeError):  # its loop has closed
                    wait.loop.call_soon_threadsafe(wait.timed_out.set)

    def until_waiting(self, threads: int = 1, *, entered: int = 0, limit_s: float = 10.0) -> bool:
        """Block until ``threads`` threads are inside :meth:`wait`, and waits have been
        entered ``entered`` times in all (a test's hand-off point: advance the clock only
        once the worker waits; after an advance, ``entered`` says the worker finished its
        round and waits again). False if that took over ``limit_s`` real seconds, so a
        broken worker fails a test instead of hanging it."""
        with self._lock:
            return self._lock.wait_for(
                lambda: self._waiting >= threads and self._entered >= entered, timeout=limit_s
            )


class _AsyncWait:
    """One coroutine waiting on a :class:`VirtualClock`: its loop and its deadline."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self.deadline_s = 0.0
        self.timed_out = asyncio.Event()


def stopwatch() -> float:
    """A high-resolution counter in seconds for measuring how long work took (statistics only)."""
    return time.perf_counter()
