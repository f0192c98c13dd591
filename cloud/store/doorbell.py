"""Waking long-polls and live pages in this process when something happens to a robot's
commands.

A waiter also looks at the ledger again every ``recheck_s`` (a command queued by another
worker whose notification was lost, say), so a doorbell only makes delivery sooner.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable

from engine.clock import Clock, ClockEvent


class Doorbell:
    """One bell per robot id; ``ring`` wakes everyone waiting on it."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self._events: dict[int, list[ClockEvent]] = {}
        self._lock = threading.Lock()

    def ring(self, robot_id: int) -> None:
        with self._lock:
            waiting = self._events.pop(robot_id, [])
        for event in waiting:
            event.set()

    def ring_everyone(self) -> None:
        with self._lock:
            waiting = [event for events in self._events.values() for event in events]
            self._events.clear()
        for event in waiting:
            event.set()

    def wait(self, robot_ids: int | Iterable[int], timeout_s: float) -> bool:
        """Until one of the robots' bells rings or ``timeout_s`` passes; True if one rang."""
        ids = [robot_ids] if isinstance(robot_ids, int) else list(robot_ids)
        event = self.clock.event()
        with self._lock:
            for robot_id in ids:
                self._events.setdefault(robot_id, []).append(event)
        rang = self.clock.wait(event, timeout_s)
        with self._lock:
            for robot_id in ids:
                waiting = self._events.get(robot_id, [])
                if event in waiting:
                    waiting.remove(event)
                if not waiting:
                    self._events.pop(robot_id, None)
        return rang
