"""Jobs: handles on work a service does while the tree keeps ticking.

A node submits work in ``initialise()`` and asks :meth:`Job.done` in each ``update()``,
returning RUNNING until it is done. Nothing here blocks.
"""

from __future__ import annotations

from concurrent.futures import CancelledError, Future
from typing import Any, Protocol

from engine.clock import Clock


class Job(Protocol):
    """Work in progress in a service."""

    def done(self) -> bool:
        """True once the work finished, failed or was cancelled."""
        ...

    def error(self) -> BaseException | None:
        """Why the work failed (None when it succeeded or is not done)."""
        ...

    def result(self) -> Any:
        """What the work produced (None for most actions); only valid once done."""
        ...

    def cancel(self) -> None:
        """Stop the work if it is still going (a pre-empted node calls this)."""
        ...


class ImmediateJob:
    """Work that finished when it was submitted, with a result or an error."""

    def __init__(self, result: Any = None, error: BaseException | None = None) -> None:
        self._result = result
        self._error = error

    def done(self) -> bool:
        return True

    def error(self) -> BaseException | None:
        return self._error

    def result(self) -> Any:
        return self._result

    def cancel(self) -> None:
        """Already done."""


class TimedJob:
    """Work that takes a known time on the clock (speaking a phrase, a servo move)."""

    def __init__(self, clock: Clock, seconds: float, result: Any = None) -> None:
        self._clock = clock
        self.finishes_at_s = clock.now() + max(0.0, seconds)
        self._result = result
        self.cancelled = False

    def done(self) -> bool:
        return self.cancelled or self._clock.now() >= self.finishes_at_s

    def error(self) -> BaseException | None:
        return CancelledError("cancelled") if self.cancelled else None

    def result(self) -> Any:
        return self._result

    def cancel(self) -> None:
        if not self.done():
            self.cancelled = True


class FutureJob:
    """Work running in a worker thread, seen through a ``concurrent.futures.Future``."""

    def __init__(self, future: Future[Any]) -> None:
        self._future = future

    def done(self) -> bool:
        return self._future.done()

    def error(self) -> BaseException | None:
        if not self._future.done():
            return None
        if self._future.cancelled():
            return CancelledError("cancelled")
        return self._future.exception()

    def result(self) -> Any:
        return self._future.result() if self.error() is None else None

    def cancel(self) -> None:
        self._future.cancel()
