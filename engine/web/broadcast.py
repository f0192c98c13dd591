"""Handing what the robot's threads publish to every page's stream on the event loop.

One bounded log, written once whatever the number of pages: publishing is O(1) and never
waits (a tick must not wait for a browser, nor pay for each page watching). Each page reads
from its own place in the log on the event loop, holding no thread; a page that fell so far
behind that the log dropped what it had not read is told so (it fetches the whole state
again). Waiting pages are woken with one call per event loop however many they are, and
an item's text for the page is made once, by the first page that sends it.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from itertools import islice
from typing import Generic, TypeVar

from engine.clock import Clock

T = TypeVar("T")


@dataclass(frozen=True)
class Taken(Generic[T]):
    """What a read found: the items in the order published, and whether older ones were
    lost to this reader (it fell behind by more than the log holds)."""

    items: list[T]
    overflowed: bool


@dataclass
class Reader:
    """One page's place in the log: the number of the next item it reads."""

    next: int


@dataclass
class Published(Generic[T]):
    """An item as published, with its text for the pages made once (``text_of`` it)."""

    item: T
    _text: str | None = field(default=None, repr=False)

    def text(self, text_of: Callable[[T], str]) -> str:
        if self._text is None:
            self._text = text_of(self.item)
        return self._text


class Broadcast(Generic[T]):
    """The last ``capacity`` items published, for any number of readers."""

    def __init__(self, clock: Clock, capacity: int) -> None:
        self.clock = clock
        self.capacity = capacity
        self._items: deque[Published[T]] = deque(maxlen=capacity)
        self._next = 0  # the number the next item published gets
        self._closed = False
        self._lock = threading.Lock()
        self._waiting: dict[asyncio.AbstractEventLoop, list[asyncio.Event]] = {}

    def publish(self, item: T) -> None:
        """From any thread, never waiting; a closed broadcast takes nothing more."""
        with self._lock:
            if self._closed:
                return
            self._items.append(Published(item))
            self._next += 1
            waiting, self._waiting = self._waiting, {}
        _wake(waiting)

    def close(self) -> None:
        """Readers read what is left, then hear that nothing more will come."""
        with self._lock:
            self._closed = True
            waiting, self._waiting = self._waiting, {}
        _wake(waiting)

    def reader(self) -> Reader:
        """A new reader, reading what is published from now on."""
        with self._lock:
            return Reader(self._next)

    async def take(self, reader: Reader, timeout_s: float) -> Taken[Published[T]] | None:
        """What ``reader`` has not read yet (at once when there is some); no items when
        nothing came within ``timeout_s`` (clock seconds); None once closed and read."""
        with self._lock:
            if reader.next < self._next or self._closed:
                return self._read(reader)
            woken = asyncio.Event()
            loop = asyncio.get_running_loop()
            self._waiting.setdefault(loop, []).append(woken)
        try:
            await self.clock.wait_async(woken, timeout_s)
        finally:
            with self._lock:
                events = self._waiting.get(loop, [])
                if woken in events:
                    events.remove(woken)
        with self._lock:
            return self._read(reader)

    def _read(self, reader: Reader) -> Taken[Published[T]] | None:
        if reader.next >= self._next and self._closed:
            return None
        first = self._next - len(self._items)
        overflowed = reader.next < first
        start = max(reader.next, first) - first
        items = list(islice(self._items, start, None))
        reader.next = self._next
        return Taken(items, overflowed)


def _wake(waiting: dict[asyncio.AbstractEventLoop, list[asyncio.Event]]) -> None:
    """One call per loop sets every event waiting on it."""
    for loop, events in waiting.items():
        with contextlib.suppress(RuntimeError):  # its loop has closed
            loop.call_soon_threadsafe(_set_all, events)


def _set_all(events: list[asyncio.Event]) -> None:
    for event in events:
        event.set()
