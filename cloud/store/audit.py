"""The audit log: what people did (commands sent or canceled, accounts changed), who did it
in which role, on which robot, when, and from which address. Rows are only ever added: the
service has no way to change or delete one, and the database refuses it (migration 0003)."""

from __future__ import annotations

import datetime as dt
from dataclasses import asdict, dataclass
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from cloud.store.database import Database
from cloud.store.tables import AuditRow
from engine.clock import Clock


@dataclass(frozen=True)
class Actor:
    """Who acts: an account's ``name`` and ``role``, and the ``client`` address it came
    from (``local`` for `vest cloud` on the service's host)."""

    name: str
    role: str
    client: str


@dataclass(frozen=True)
class AuditEntry:
    """One line of the log; ``at_s`` is seconds since the epoch (UTC)."""

    at_s: float
    actor: str
    role: str
    action: str
    robot: str | None
    detail: str
    client: str

    def line(self) -> str:
        """The entry as one plain line: when (UTC), who, from where, what."""
        when = dt.datetime.fromtimestamp(self.at_s, dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
        on = f" robot {self.robot}" if self.robot else ""
        detail = f": {self.detail}" if self.detail else ""
        return f"{when} {self.actor} ({self.role}) from {self.client}: {self.action}{on}{detail}"

    def as_json(self) -> dict[str, Any]:
        return asdict(self)


class AuditLog:
    """Entries of the log in ``db``, timed by ``clock``."""

    def __init__(self, db: Database, clock: Clock) -> None:
        self.db = db
        self.clock = clock

    def write(
        self,
        session: Session,
        by: Actor,
        action: str,
        *,
        robot: str | None = None,
        detail: str = "",
    ) -> None:
        """Adds an entry within ``session``'s transaction (kept only if the change is)."""
        session.add(
            AuditRow(
                at_s=self.clock.now(),
                actor=by.name[:64],
                role=by.role[:16],
                action=action[:32],
                robot=robot,
                detail=detail[:500],
                client=by.client[:64],
            )
        )

    def record(self, by: Actor, action: str, *, robot: str | None = None, detail: str = "") -> None:
        """Adds an entry in a transaction of its own."""
        with self.db.transaction() as session:
            self.write(session, by, action, robot=robot, detail=detail)

    def since(self, since_s: float | None = None) -> list[AuditEntry]:
        """Every entry from ``since_s`` on (seconds since the epoch; None: all), oldest
        first."""
        query = select(AuditRow).order_by(AuditRow.at_s, AuditRow.id)
        if since_s is not None:
            query = query.where(AuditRow.at_s >= since_s)
        with self.db.transaction() as session:
            return [
                AuditEntry(
                    row.at_s, row.actor, row.role, row.action, row.robot, row.detail, row.client
                )
                for row in session.scalars(query)
            ]
