"""The one way vest runs a periodic worker: some work every so many seconds of a clock's
time, on a thread of its own, until stopped.

Waiting is the clock's (:meth:`~engine.clock.Clock.wait` on the worker's own stop
event), so a virtual clock drives it as it drives the scheduler, and stopping never waits
out a period. Used by hot reload, the cloud service's upkeep and whatever else must happen
every so often beside the robot or the service.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from engine.clock import Clock

log = logging.getLogger(__name__)


class Periodic:
    """``work`` every ``every_s`` seconds of ``clock``'s time, first one period after
    :meth:`start`, on a thread named ``name``; ``final``: once more when stopped. Work that
    raises is logged and the next round comes (a worker never dies of one bad round)."""

    def __init__(
        self,
        clock: Clock,
        every_s: float,
        work: Callable[[], None],
        *,
        name: str,
        final: bool = False,
    ) -> None:
        self.clock = clock
        self.every_s = every_s
        self.work = work
        self.name = name
        self.final = final
        self._stop = clock.event()
        self._thread: threading.Thread | None = None

    @property
    def running(self) -> bool:
        return self._thread is not None

    def start(self) -> None:
        """Begin (again, after a stop); a worker already running is left as it is."""
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
            self._thread.start()

    def stop(self) -> None:
        """End the worker (a round in progress finishes first), then the final round."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
            if self.final:
                self._round()

    def _run(self) -> None:
        while not self.clock.wait(self._stop, self.every_s):
            self._round()

    def _round(self) -> None:
        try:
            self.work()
        except Exception:
            log.exception("%s: one round failed; the next comes in %g s", self.name, self.every_s)
