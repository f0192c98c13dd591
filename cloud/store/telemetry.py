"""The latest telemetry of each robot, and when each robot last called in.

Robots push every second; writing each push at once would make the database the
bottleneck (200 robots: 200 transactions a second). The latest values are kept in memory
and written in one batch by ``flush()`` (the service calls it every ``flush_s``, and when it
stops): one row per robot that pushed, its stored keys merged with the new ones. Reads
merge memory over the database, so this worker always answers with the newest it has
heard; another worker sharing a PostgreSQL database sees it after the next flush (robots
push every key every second, so a worker's batch is never more than a push behind).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from sqlalchemy import bindparam, select, update
from sqlalchemy.dialects import postgresql, sqlite
from sqlalchemy.orm import Session

from cloud.store.database import Database
from cloud.store.tables import Table, TelemetryRow
from engine.clock import Clock

Reading = dict[str, Any]  # {"value": ..., "at_s": seconds since the epoch}
MAX_KEYS = 500
"""Keys a robot's telemetry may hold in all (its pushes update them; a push that would add
more is refused): what a robot reports is bounded, however often it pushes."""


class TelemetryFullError(ValueError):
    """A push would give a robot more than :data:`MAX_KEYS` telemetry keys."""


_robots = Table.metadata.tables["robots"]
_SEEN = (
    update(_robots)
    .where(_robots.c.id == bindparam("robot"))
    .where(_robots.c.last_seen_s.is_(None) | (_robots.c.last_seen_s < bindparam("at")))
    .values(last_seen_s=bindparam("at"))
)
"""A robot's last_seen_s moves forward only (workers flush in any order)."""


class Telemetry:
    def __init__(self, db: Database, clock: Clock) -> None:
        self.db = db
        self.clock = clock
        self._lock = threading.Lock()
        self._polls_changed = threading.Condition(self._lock)
        self._latest: dict[int, dict[str, Reading]] = {}
        self._seen: dict[int, float] = {}
        self._unwritten: dict[int, dict[str, Reading]] = {}
        self._unwritten_seen: dict[int, float] = {}
        self._polling: dict[int, int] = {}
        self._newest_poll: dict[int, int] = {}
        self._keys: dict[int, set[str]] = {}
        """Each robot's telemetry keys so far (the database's, and this worker's since)."""

    def put(self, robot_id: int, values: dict[str, Any]) -> None:
        """Keep ``values`` as the robot's latest, stamped now; the robot was seen now.
        TelemetryFullError (nothing kept) when the robot would hold more than
        :data:`MAX_KEYS` keys."""
        if not values:
            self.seen(robot_id)
            return
        if not self.knows(robot_id):
            self.learn(robot_id)
        known = self._keys[robot_id]
        now = self.clock.now()
        with self._lock:
            new = [key for key in values if key not in known]
            if len(known) + len(new) > MAX_KEYS:
                raise TelemetryFullError(
                    f"this robot's telemetry holds {len(known)} keys and may hold {MAX_KEYS}: "
                    f"a push updates them, it cannot add {len(new)} more ({new[0]!r}...)"
                )
            known.update(new)
            latest = self._latest.setdefault(robot_id, {})
            unwritten = self._unwritten.setdefault(robot_id, {})
            for key, value in values.items():
                latest[key] = unwritten[key] = {"value": value, "at_s": now}
            self._seen[robot_id] = self._unwritten_seen[robot_id] = now

    def knows(self, robot_id: int) -> bool:
        """Whether this worker knows the robot's telemetry keys (no database needed)."""
        with self._lock:
            return robot_id in self._keys

    def learn(self, robot_id: int) -> None:
        """Read the robot's stored telemetry keys (once a worker: the database)."""
        stored = set(self._stored(robot_id))
        with self._lock:
            self._keys.setdefault(robot_id, stored)

    def seen(self, robot_id: int) -> None:
        """The robot called in now (a long-poll counts)."""
        now = self.clock.now()
        with self._lock:
            self._seen[robot_id] = self._unwritten_seen[robot_id] = now

    @contextmanager
    def polling(self, robot_id: int) -> Iterator[Callable[[], bool]]:
        """The robot is waiting in a long-poll: it is seen when it starts and ends, and
        online all along. Yields ``superseded()``: True once the same robot started a newer
        long-poll in this worker (this one's client gave up: it must not take a command)."""
        self.seen(robot_id)
        with self._lock:
            self._polling[robot_id] = self._polling.get(robot_id, 0) + 1
            self._newest_poll[robot_id] = poll = self._newest_poll.get(robot_id, 0) + 1
            self._polls_changed.notify_all()
        try:
            yield lambda: self._newest_poll.get(robot_id) != poll
        finally:
            with self._lock:
                self._polling[robot_id] -= 1
                if not self._polling[robot_id]:
                    del self._polling[robot_id]
            self.seen(robot_id)

    def is_polling(self, robot_id: int) -> bool:
        """True while the robot waits in a long-poll of this worker."""
        with self._lock:
            return robot_id in self._polling

    def wait_until_polling(self, robot_id: int, timeout_s: float) -> bool:
        """Block (real seconds) until the robot waits in a long-poll of this worker; False
        when it did not within ``timeout_s``."""
        with self._polls_changed:
            return self._polls_changed.wait_for(lambda: robot_id in self._polling, timeout_s)

    def _stored(self, robot_id: int) -> dict[str, Reading]:
        """The robot's telemetry as the database has it."""
        with self.db.transaction() as session:
            row = session.get(TelemetryRow, robot_id)
            return dict(row.readings) if row is not None else {}

    def latest(self, robot_id: int) -> dict[str, Reading]:
        """key -> {"value", "at_s"}, sorted by key."""
        stored = self._stored(robot_id)
        with self._lock:
            for key, reading in self._latest.get(robot_id, {}).items():
                if key not in stored or stored[key]["at_s"] <= reading["at_s"]:
                    stored[key] = reading
        return dict(sorted(stored.items()))

    def last_seen(self, robot_id: int, stored_s: float | None) -> float | None:
        """When the robot last called in: this worker's memory or ``stored_s`` (the
        database's), whichever is newer."""
        with self._lock:
            heard_s = self._seen.get(robot_id)
        if heard_s is None or (stored_s is not None and stored_s > heard_s):
            return stored_s
        return heard_s

    def flush(self) -> int:
        """Write what came in since the last flush, in one transaction: each robot that
        pushed gets its stored readings merged with the new ones (the newer reading of a key
        wins; keys another worker or an earlier run stored stay). Returns how many new values
        went in."""
        with self._lock:
            values, self._unwritten = self._unwritten, {}
            seen, self._unwritten_seen = self._unwritten_seen, {}
        if not values and not seen:
            return 0
        try:
            with self.db.transaction() as session:
                if values:
                    session.execute(self._upsert(), self._merged(session, values))
                if seen:
                    session.connection().execute(
                        _SEEN, [{"robot": robot, "at": at_s} for robot, at_s in seen.items()]
                    )
        except Exception:
            self._unwrite(values, seen)  # kept for the next flush
            raise
        return sum(len(readings) for readings in values.values())

    def _merged(
        self, session: Session, values: dict[int, dict[str, Reading]]
    ) -> list[dict[str, Any]]:
        """A row for each robot in ``values``: what is stored, updated with ``values`` (on
        PostgreSQL the stored rows are locked: two workers flushing at once both count)."""
        query = select(TelemetryRow.robot_id, TelemetryRow.readings).where(
            TelemetryRow.robot_id.in_(values)
        )
        if self.db.is_postgresql:
            query = query.with_for_update()
        stored = {robot_id: dict(readings) for robot_id, readings in session.execute(query)}
        rows = []
        for robot_id, readings in values.items():
            merged = stored.get(robot_id, {})
            for key, reading in readings.items():
                if key not in merged or merged[key]["at_s"] <= reading["at_s"]:
                    merged[key] = reading
            at_s = max(reading["at_s"] for reading in merged.values())
            rows.append({"robot_id": robot_id, "readings": merged, "at_s": at_s})
        return rows

    def _unwrite(self, values: dict[int, dict[str, Reading]], seen: dict[int, float]) -> None:
        with self._lock:
            for robot_id, readings in values.items():
                newer = self._unwritten.setdefault(robot_id, {})
                for key, reading in readings.items():
                    newer.setdefault(key, reading)
            for robot_id, at_s in seen.items():
                self._unwritten_seen.setdefault(robot_id, at_s)

    def _upsert(self) -> Any:
        insert = postgresql.insert if self.db.is_postgresql else sqlite.insert
        statement = insert(TelemetryRow)
        return statement.on_conflict_do_update(
            index_elements=[TelemetryRow.robot_id],
            set_={"readings": statement.excluded.readings, "at_s": statement.excluded.at_s},
        )
