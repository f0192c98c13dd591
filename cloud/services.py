"""What the service's endpoints work with, built once per app and injected."""

from __future__ import annotations

from dataclasses import dataclass

from cloud.settings import Settings
from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.doorbell import Doorbell
from cloud.store.ledger import CommandLedger
from cloud.store.telemetry import Telemetry
from engine.clock import Clock


@dataclass
class CloudStore:
    settings: Settings
    clock: Clock
    db: Database
    directory: Directory
    ledger: CommandLedger
    telemetry: Telemetry
    doorbell: Doorbell

    @classmethod
    def open(cls, settings: Settings, clock: Clock) -> CloudStore:
        db = Database(settings.db_url)
        return cls(
            settings,
            clock,
            db,
            Directory(db),
            CommandLedger(
                db, clock, lease_s=settings.lease_s, default_timeout_s=settings.default_timeout_s
            ),
            Telemetry(db, clock),
            Doorbell(clock),
        )

    def close(self) -> None:
        self.db.close()
