"""The service's upkeep, every ``flush_s``, on a periodic worker (:mod:`engine.periodic`):
the telemetry kept in memory is written, and commands whose lease or timeout ran out are
stored so (reads never write)."""

from __future__ import annotations

import logging

from sqlalchemy.exc import SQLAlchemyError

from cloud.store.ledger import CommandLedger
from cloud.store.telemetry import Telemetry
from engine.clock import Clock
from engine.periodic import Periodic

log = logging.getLogger(__name__)


class Upkeep:
    """Every ``flush_s`` until closed (and once more then): flushes ``telemetry`` and lets
    ``ledger`` expire what ran out (an operator's page hears of a command that timed out
    though nobody wrote to it)."""

    def __init__(
        self, telemetry: Telemetry, ledger: CommandLedger, clock: Clock, flush_s: float
    ) -> None:
        self.telemetry = telemetry
        self.ledger = ledger
        self.clock = clock
        self.flush_s = flush_s
        self._worker = Periodic(clock, flush_s, self._flush, name="cloud-upkeep", final=True)
        self._worker.start()

    def close(self) -> None:
        """Stop, after one more flush."""
        self._worker.stop()

    def _flush(self) -> None:
        try:
            self.telemetry.flush()
        except SQLAlchemyError as error:  # kept in memory; the next flush tries again
            log.warning("could not write telemetry (%s); trying again", error)
        try:
            self.ledger.expire_due()
        except SQLAlchemyError as error:  # what ran out still reads so; stored next time
            log.warning("could not store expired commands (%s); trying again", error)
