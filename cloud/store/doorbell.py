"""Waking long-polls in this process when a robot's command arrives.

A waiting robot also re-checks the ledger every ``recheck_s`` (a command queued by another
worker process, or a notification missed), so a doorbell only makes delivery sooner.
"""

from __future__ import annotations

import threading

from engine.clock import Clock, ClockEvent


class Doorbell:
    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self._events: dict[int, list[ClockEvent]] = {}
        self._lock = threading.Lock()

    def ring(self, robot_id: int) -> None:
        with self._lock:
            waiting = self._events.pop(robot_id, [])
        for event in waiting:
            event.set()

    def wait(self, robot_id: int, timeout_s: float) -> bool:
        """Until the robot's doorbell rings or ``timeout_s`` passes; True if it rang."""
        event = self.clock.event()
        with self._lock:
            self._events.setdefault(robot_id, []).append(event)
        rang = self.clock.wait(event, timeout_s)
        with self._lock:
            waiting = self._events.get(robot_id, [])
            if event in waiting:
                waiting.remove(event)
        return rang
