"""Work in progress off the clock, so a virtual clock can wait for it.

On a real clock the speech workers run beside the ticks. On a virtual clock (``vest run
--fast``, tests) time would race past work that takes real time (synthesis,
recognition), so before each tick the scheduler waits until every worker is *settled*:
idle, or waiting on the clock for a time still to come. A run is then the same on every
machine.
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class Settling:
    """Workers say when their state changed; a waiter waits until they are all settled."""

    def __init__(self) -> None:
        self._changed = threading.Condition()

    def changed(self) -> None:
        with self._changed:
            self._changed.notify_all()

    def wait(self, settled: Callable[[], bool], timeout_s: float = 120.0) -> bool:
        """Block (in real time) until ``settled()``; False after ``timeout_s``."""
        with self._changed:
            return self._changed.wait_for(settled, timeout=timeout_s)
