"""Clocks: the only place in the engine that reads time or sleeps.

Everything else receives a :class:`Clock` and asks it. ``RealClock`` follows the machine's
monotonic clock; ``VirtualClock`` only moves when told to, so a test can advance ten
seconds in a millisecond and a scenario can run as fast as the machine allows.
All times are in seconds.
"""

from __future__ import annotations

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

    def sleep_until(self, deadline_s: float) -> None:
        """Wait until :meth:`now` reaches ``deadline_s`` (returns at once if it has)."""
        ...

    def wake(self) -> None:
        """Cut short any sleep in progress, and every later one: the engine is shutting down."""
        ...


class RealClock:
    """The machine's monotonic clock; sleeps can be woken early by :meth:`wake`."""

    def __init__(self) -> None:
        self._woken = threading.Event()

    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            self._woken.wait(seconds)

    def sleep_until(self, deadline_s: float) -> None:
        self.sleep(deadline_s - time.monotonic())

    def wake(self) -> None:
        self._woken.set()


class VirtualClock:
    """A clock that moves only when advanced; sleeping advances it.

    Used by tests and by ``vest run --fast``: ``sleep_until(t)`` jumps straight to ``t``.
    Thread-safe, so a worker thread may read it while the owner advances it.
    """

    def __init__(self, start_s: float = 0.0) -> None:
        self._now = start_s
        self._lock = threading.Lock()

    def now(self) -> float:
        return self._now

    def advance(self, seconds: float) -> None:
        """Move time forward by ``seconds`` (must not be negative)."""
        if seconds < 0:
            raise ValueError(f"a clock cannot go backwards: advance({seconds})")
        with self._lock:
            self._now += seconds

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            self.advance(seconds)

    def sleep_until(self, deadline_s: float) -> None:
        with self._lock:
            self._now = max(self._now, deadline_s)

    def wake(self) -> None:
        """Nothing sleeps for real on a virtual clock."""


def stopwatch() -> float:
    """A high-resolution counter in seconds for measuring how long work took (statistics only)."""
    return time.perf_counter()
