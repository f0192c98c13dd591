"""Handing items from the robot's threads to a page's stream on the event loop.

The giver never waits (a tick must not wait for a browser): a full mailbox drops its
oldest item and remembers that it did, so the stream can tell its page to fetch the whole
state again. The taker awaits on the event loop, holding no thread, and wakes at once when
something is given.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections import deque
from dataclasses import dataclass
from typing import Generic, TypeVar

from engine.clock import Clock

T = TypeVar("T")


@dataclass(frozen=True)
class Taken(Generic[T]):
    """What a take found: the items in the order given, and whether older ones were lost."""

    items: list[T]
    overflowed: bool


class Mailbox(Generic[T]):
    """At most ``capacity`` items waiting for one reader."""

    def __init__(self, clock: Clock, capacity: int) -> None:
        self.clock = clock
        self.capacity = capacity
        self._items: deque[T] = deque()
        self._lock = threading.Lock()
        self._closed = False
        self._overflowed = False
        self._reader: tuple[asyncio.AbstractEventLoop, asyncio.Event] | None = None

    def give(self, item: T) -> None:
        """From any thread, never waiting; a closed mailbox takes nothing more."""
        with self._lock:
            if self._closed:
                return
            if len(self._items) >= self.capacity:
                self._items.popleft()
                self._overflowed = True
            self._items.append(item)
            reader, self._reader = self._reader, None
        _wake(reader)

    def close(self) -> None:
        """The reader takes what is left, then hears that nothing more will come."""
        with self._lock:
            self._closed = True
            reader, self._reader = self._reader, None
        _wake(reader)

    async def take(self, timeout_s: float) -> Taken[T] | None:
        """Everything waiting (at once when there is some); no items when nothing came
        within ``timeout_s`` (clock seconds); None once closed and emptied."""
        with self._lock:
            if not (self._items or self._closed):
                woken = asyncio.Event()
                self._reader = (asyncio.get_running_loop(), woken)
            else:
                return self._drain()
        try:
            await self.clock.wait_async(woken, timeout_s)
        finally:
            with self._lock:
                self._reader = None
        with self._lock:
            return self._drain()

    def _drain(self) -> Taken[T] | None:
        if not self._items and self._closed:
            return None
        taken = Taken(list(self._items), self._overflowed)
        self._items.clear()
        self._overflowed = False
        return taken


def _wake(reader: tuple[asyncio.AbstractEventLoop, asyncio.Event] | None) -> None:
    if reader is not None:
        loop, woken = reader
        with contextlib.suppress(RuntimeError):  # its loop has closed
            loop.call_soon_threadsafe(woken.set)
