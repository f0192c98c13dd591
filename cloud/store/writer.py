"""Writing the telemetry kept in memory to the database, every ``flush_s``, in a thread."""

from __future__ import annotations

import logging
import threading

from sqlalchemy.exc import SQLAlchemyError

from cloud.store.telemetry import Telemetry
from engine.clock import Clock

log = logging.getLogger(__name__)


class TelemetryWriter:
    """Flushes ``telemetry`` every ``flush_s`` until closed, and once more then."""

    def __init__(self, telemetry: Telemetry, clock: Clock, flush_s: float) -> None:
        self.telemetry = telemetry
        self.clock = clock
        self.flush_s = flush_s
        self._stop = clock.event()
        self._thread = threading.Thread(target=self._run, name="telemetry-writer", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=10)
        self._flush()

    def _run(self) -> None:
        while not self.clock.wait(self._stop, self.flush_s):
            self._flush()

    def _flush(self) -> None:
        try:
            self.telemetry.flush()
        except SQLAlchemyError as error:  # kept in memory; the next flush tries again
            log.warning("could not write telemetry (%s); trying again", error)
