"""What the service's endpoints work with, built once per app and injected."""

from __future__ import annotations

from dataclasses import dataclass

from cloud.settings import Settings
from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.doorbell import Doorbell
from cloud.store.ledger import CommandLedger
from cloud.store.notifications import Announcer, PostgresListener
from cloud.store.principal_cache import PrincipalCache
from cloud.store.session_views import SessionViews
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
    sessions: SessionViews
    listener: PostgresListener | None = None

    def __post_init__(self) -> None:
        self.closing = self.clock.event()
        self.principals = PrincipalCache(
            self.directory, self.clock, ttl_s=self.settings.token_cache_s
        )

    @classmethod
    def open(cls, settings: Settings, clock: Clock) -> CloudStore:
        db = Database(settings.db_url)
        doorbell = Doorbell(clock)
        announcer = Announcer(doorbell, postgresql=db.is_postgresql)
        ledger = CommandLedger(
            db,
            clock,
            lease_s=settings.lease_s,
            default_timeout_s=settings.default_timeout_s,
            listener=announcer,
        )
        listener = PostgresListener(db.engine, doorbell, clock) if db.is_postgresql else None
        return cls(
            settings,
            clock,
            db,
            Directory(db, clock),
            ledger,
            Telemetry(db, clock),
            doorbell,
            SessionViews(db, clock, announcer),
            listener,
        )

    def begin_closing(self) -> None:
        """The service is stopping: live streams end now (waiting long-polls answer 204)."""
        self.closing.set()
        self.doorbell.ring_everyone()

    def close(self) -> None:
        if self.listener is not None:
            self.listener.close()
        self.db.close()
