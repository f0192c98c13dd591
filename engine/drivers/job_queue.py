"""Transactions waiting for the bus: the job, the queue in the manager's order, a refusal.

A :class:`~engine.drivers.bus_manager.BusManager` queues each submitted transaction as a
:class:`Job` in a :class:`JobQueue`: on-request reads before routine polls, first come
first served within a priority.
"""

from __future__ import annotations

import contextlib
import heapq
import itertools
from collections.abc import Callable
from concurrent.futures import Future, InvalidStateError
from dataclasses import dataclass
from typing import Any

from engine.drivers.bus_policy import Priority

__all__ = ["Job", "JobQueue", "fail_future"]


@dataclass(slots=True)
class Job:
    """One transaction: ``fn(bus)`` for ``device``, its future and its priority."""

    device: str
    fn: Callable[[Any], Any]
    future: Future[Any]
    priority: Priority


class JobQueue:
    """Jobs by priority, then in the order they came (not thread-safe: the owner locks)."""

    def __init__(self) -> None:
        self._heap: list[tuple[int, int, Job]] = []
        self._sequence = itertools.count()

    def __len__(self) -> int:
        return len(self._heap)

    def push(self, job: Job) -> None:
        heapq.heappush(self._heap, (job.priority, next(self._sequence), job))

    def pop(self) -> Job:
        """The most urgent job, the oldest of its priority."""
        return heapq.heappop(self._heap)[2]

    def drain(self) -> list[Job]:
        """Every job still queued, in the order they would have run; the queue is emptied."""
        jobs = [job for _, _, job in sorted(self._heap, key=lambda entry: entry[:2])]
        self._heap.clear()
        return jobs


def fail_future(future: Future[Any], error: BaseException) -> None:
    """Fail ``future`` unless its caller cancelled it meanwhile."""
    with contextlib.suppress(InvalidStateError):
        future.set_exception(error)
