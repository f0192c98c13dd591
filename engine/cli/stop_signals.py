"""Ctrl-C (SIGINT) and SIGTERM, handled from a command's first moment to its last.

:class:`StopSignals` is installed before anything slow (importing the engine, building
the robot), so a signal at any moment ends a command the same way: ``vest run`` asks its
scheduler to stop (at once if the robot is not running yet) and ends cleanly, with its
statistics; the other commands stop where they are and say "interrupted". A second signal
while stopping stops at once (for a shutdown that hangs).
"""

from __future__ import annotations

import signal
from collections.abc import Callable
from types import FrameType
from typing import Any

HANDLED = (signal.SIGINT, signal.SIGTERM)


class StopSignals:
    """Turns SIGINT and SIGTERM into a stop request; remembers one that came early."""

    def __init__(self) -> None:
        self.received: int | None = None
        """The first signal received, or None."""
        self._callbacks: list[Callable[[], None]] = []
        self._interrupt = False
        self._previous: dict[int, Any] = {}

    def install(self) -> bool:
        """Handle SIGINT and SIGTERM from now on; False where that is not possible (not
        the main thread). A signal held pending by the parent's signal mask arrives now."""
        try:
            for sig in HANDLED:
                self._previous[sig] = signal.signal(sig, self._handle)
        except ValueError:  # signal handlers can only be set in the main thread
            self.restore()
            return False
        signal.pthread_sigmask(signal.SIG_UNBLOCK, HANDLED)
        return True

    def restore(self) -> None:
        """Put back the handlers that were there before :meth:`install`."""
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()

    def on_stop(self, callback: Callable[[], None]) -> None:
        """Call ``callback`` (safe in a signal handler) when a signal comes; at once when
        one came already."""
        self._callbacks.append(callback)
        if self.received is not None:
            callback()

    def interrupt(self) -> None:
        """From now on a signal raises KeyboardInterrupt where the program is (commands
        with nothing to shut down); raises it now when a signal came already."""
        self._interrupt = True
        if self.received is not None:
            raise KeyboardInterrupt

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        again = self.received is not None
        if self.received is None:
            self.received = signum
        if again or self._interrupt:
            raise KeyboardInterrupt
        for callback in self._callbacks:
            callback()


def serve_until_stopped() -> None:
    """Wait, doing nothing, until Ctrl-C or SIGTERM ends the command (a page's server runs
    in its threads meanwhile: `vest replay --view`, `vest edit`)."""
    from engine.clock import RealClock

    clock = RealClock()
    forever = clock.event()
    while not clock.wait(forever, 3600.0):
        pass
