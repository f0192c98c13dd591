"""Items handed from the scheduler's thread to a worker thread beside it, never waited for.

What the recorder and Foxglove's live server share: ``put`` never blocks the tick (a full
queue drops the item and counts it); the worker takes every item waiting at once, as one
batch, and hands it to ``handle``, which returns False to take no more (a full disk).
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from typing import Generic, TypeVar

Item = TypeVar("Item")


class Handoff(Generic[Item]):
    """A bounded queue of at most ``capacity`` items and the thread ``name`` that hands
    them, in batches of at most ``batch`` items, to ``handle``."""

    def __init__(
        self,
        name: str,
        handle: Callable[[list[Item]], bool],
        *,
        capacity: int,
        batch: int = 5000,
    ) -> None:
        self.dropped = 0
        """Items dropped because the queue was full (the worker fell behind)."""
        self._handle, self._batch = handle, batch
        self._queue: queue.Queue[Item | None] = queue.Queue(maxsize=capacity)
        self._thread = threading.Thread(target=self._work, name=name, daemon=True)
        self._stopped = False

    def start(self) -> None:
        self._thread.start()

    def put(self, item: Item) -> None:
        """Queued for the worker; dropped and counted when the queue is full."""
        if self._stopped:
            return
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            self.dropped += 1

    def close(self) -> None:
        """Everything queued is handled (or, after ``handle`` refused, let go), then the
        worker ends."""
        if self._thread.is_alive():
            self._queue.put(None)  # the worker takes everything until this, whatever came
            self._thread.join()

    def _work(self) -> None:
        closing = False
        while not closing:
            batch: list[Item] = []
            waiting = [self._queue.get()]
            while len(waiting) < self._batch:  # everything already waiting, then one hand-over
                try:
                    waiting.append(self._queue.get_nowait())
                except queue.Empty:
                    break
            for item in waiting:
                if item is None:
                    closing = True
                else:
                    batch.append(item)
            if batch and not self._stopped and not self._handle(batch):
                self._stopped = True  # takes on, handling nothing, until it is closed
