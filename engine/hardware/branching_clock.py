"""Time for inline hardware runs: a poll's waits happen beside the robot, not before it.

On the robot each poller has its own thread: while the VL53L0X driver waits 33 ms for a
measurement, the trees tick and the other pollers poll. Run inline on a
:class:`~engine.clock.VirtualClock` (``vest run --fast``, tests), every poll runs in the
scheduler's thread, and a driver's ``clock.sleep`` would push the whole robot's time
forward: three range sensors at 10 Hz would add a second of waiting to every second.

:class:`BranchingClock` keeps both right. Inside :meth:`BranchingClock.branch` a sleep
moves only the branch's own time, which the driver and the simulated chips (given the same
clock) both see, so a conversion still takes its time on the chip; when the branch ends,
the thread is back at the robot's time, as if the poll had run on a thread of its own.
Outside a branch it is the clock it wraps. Only the thread inside a branch sees the
branch's time.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import Iterator

from engine.clock import Clock, ClockEvent


class BranchingClock:
    """A :class:`~engine.clock.Clock` whose sleeps inside :meth:`branch` stay in the branch."""

    def __init__(self, base: Clock) -> None:
        self.base = base
        self._local = threading.local()

    def _offset(self) -> float | None:
        return getattr(self._local, "offset", None)

    def now(self) -> float:
        offset = self._offset()
        return self.base.now() + (offset or 0.0)

    def sleep(self, seconds: float) -> None:
        offset = self._offset()
        if offset is None:
            self.base.sleep(seconds)
        elif seconds > 0:
            self._local.offset = offset + seconds

    def sleep_until(self, deadline_s: float, stop: ClockEvent | None = None) -> bool:
        if self._offset() is None:
            return self.base.sleep_until(deadline_s, stop)
        if stop is not None and stop.is_set():
            return True
        self.sleep(deadline_s - self.now())
        return False

    def event(self) -> ClockEvent:
        return self.base.event()

    def wait(self, event: ClockEvent, timeout_s: float) -> bool:
        """Waits on the robot's time (a waiting thread is never inside a branch)."""
        return self.base.wait(event, timeout_s)

    async def wait_async(self, event: asyncio.Event, timeout_s: float) -> bool:
        return await self.base.wait_async(event, timeout_s)

    @contextlib.contextmanager
    def branch(self) -> Iterator[None]:
        """Run the body on its own time line starting now; nested branches share the outer one."""
        if self._offset() is not None:
            yield
            return
        self._local.offset = 0.0
        try:
            yield
        finally:
            self._local.offset = None


def branch_of(clock: Clock) -> contextlib.AbstractContextManager[None]:
    """``clock.branch()`` for a :class:`BranchingClock`, else a context that does nothing."""
    if isinstance(clock, BranchingClock):
        return clock.branch()
    return contextlib.nullcontext()
