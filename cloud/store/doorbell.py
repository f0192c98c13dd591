"""Waking long-polls and live pages in this process when something happens to a robot's
commands.

Waiters are coroutines on the service's event loop: a waiting long-poll or stream holds no
thread. Rings come from anywhere (a request's thread, the PostgreSQL listener's thread) and
reach each waiter on its own loop. A waiter also looks at the ledger again every
``recheck_s`` (a command queued by another worker whose notification was lost, say), so a
doorbell only makes delivery sooner.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import Iterable

from engine.clock import Clock


class _Waiter:
    """One coroutine waiting: its loop, and the flag that wakes it."""

    def __init__(self) -> None:
        self.loop = asyncio.get_running_loop()
        self.rang = asyncio.Event()

    def wake(self) -> None:
        with contextlib.suppress(RuntimeError):  # its loop has closed
            self.loop.call_soon_threadsafe(self.rang.set)


class Doorbell:
    """One bell per robot id; ``ring`` wakes everyone waiting on it."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self._waiters: dict[int, list[_Waiter]] = {}
        self._lock = threading.Lock()

    def ring(self, robot_id: int) -> None:
        """Wakes every wait on ``robot_id``'s bell (from any thread)."""
        with self._lock:
            waiting = self._waiters.pop(robot_id, [])
        for waiter in waiting:
            waiter.wake()

    def ring_everyone(self) -> None:
        with self._lock:
            waiting = [waiter for waiters in self._waiters.values() for waiter in waiters]
            self._waiters.clear()
        for waiter in waiting:
            waiter.wake()

    async def wait(self, robot_ids: int | Iterable[int], timeout_s: float) -> bool:
        """Until one of the robots' bells rings or ``timeout_s`` of the clock's time passes;
        True if one rang."""
        ids = [robot_ids] if isinstance(robot_ids, int) else list(robot_ids)
        waiter = _Waiter()
        with self._lock:
            for robot_id in ids:
                self._waiters.setdefault(robot_id, []).append(waiter)
        try:
            return await self.clock.wait_async(waiter.rang, timeout_s)
        finally:
            with self._lock:
                for robot_id in ids:
                    waiting = self._waiters.get(robot_id, [])
                    if waiter in waiting:
                        waiting.remove(waiter)
                    if not waiting:
                        self._waiters.pop(robot_id, None)
