"""What the site keeps about its sessions, sealed like the recordings: ``site.db`` in its
data folder.

- ``sessions``: every recording vest made here (its path, the pseudonym it belongs to or
  '' for none, when it started, how long it lasted in seconds, the profile, what consent
  let it keep), wherever the file was written;
- ``outputs``: what was written from those sessions in the clear (reports, progress
  reports, exports, conversions), and every recording each holds (``source``: a JSON
  list), so an erasure, and the purge of any of those recordings, find them;
- ``erasing``: a person whose erasure began and has not finished (it finishes on the next
  run of any ``vest data`` command or ``vest run``);
- ``audit``: who recorded, replayed, reported, exported, erased what and when. Append-only:
  the database refuses to change or delete a line, and each line carries a SHA-256 chain
  over the one before, so a line changed with the key in hand is found
  (:meth:`SiteRecords.audit_lines` says where the chain breaks).

Times are seconds since the epoch (UTC), from the injected clock.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from engine.privacy.sealed_sqlite import Connection, connect_sealed
from engine.privacy.site_data import SiteKey

RECORDS_FILE = "site.db"
SCHEMA = """
CREATE TABLE IF NOT EXISTS sessions (
    path TEXT PRIMARY KEY, person TEXT NOT NULL, started REAL NOT NULL, length_s REAL,
    profile TEXT NOT NULL, kept TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS outputs (
    path TEXT PRIMARY KEY, person TEXT NOT NULL, kind TEXT NOT NULL, made REAL NOT NULL,
    source TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS erasing (person TEXT PRIMARY KEY, since REAL NOT NULL);
CREATE TABLE IF NOT EXISTS audit (
    seq INTEGER PRIMARY KEY, at REAL NOT NULL, who TEXT NOT NULL, action TEXT NOT NULL,
    person TEXT NOT NULL, what TEXT NOT NULL, chain TEXT NOT NULL
);
CREATE TRIGGER IF NOT EXISTS audit_is_not_changed BEFORE UPDATE ON audit
BEGIN SELECT RAISE(ABORT, 'the audit trail is append-only'); END;
CREATE TRIGGER IF NOT EXISTS audit_is_not_deleted BEFORE DELETE ON audit
BEGIN SELECT RAISE(ABORT, 'the audit trail is append-only'); END;
"""
FIRST_LINK = "0" * 64
SCHEMA_VERSION = 2


@dataclass(frozen=True)
class SessionEntry:
    """One recording in the index; ``length_s`` is None until the session ended."""

    path: Path
    person: str
    started: float
    length_s: float | None
    profile: str
    kept: tuple[str, ...]


@dataclass(frozen=True)
class AuditLine:
    """One line of the audit trail; ``intact`` is False from the first line whose chain
    does not follow from the line before (changed after it was written)."""

    seq: int
    at: float
    who: str
    action: str
    person: str
    what: str
    chain: str
    intact: bool


class SiteRecords:
    """The sealed ``site.db`` of a data folder, opened with the site's key."""

    def __init__(self, folder: Path, key: SiteKey) -> None:
        self.path = folder / RECORDS_FILE
        self._connection: Connection = connect_sealed(self.path, key)
        self.path.chmod(0o600)  # the owner's alone, as the key is
        self._connection.execute("PRAGMA busy_timeout = 10000")  # another vest writing
        self._connection.execute("PRAGMA secure_delete = ON")  # an erased row is overwritten
        self._connection.executescript(SCHEMA)
        self._upgrade()
        self._connection.commit()

    def _upgrade(self) -> None:
        """Brings a site.db of an earlier vest up to this schema (``PRAGMA user_version``)."""
        version = self._connection.execute("PRAGMA user_version").fetchone()[0]
        if version < 1:
            columns = {row[1] for row in self._connection.execute("PRAGMA table_info(outputs)")}
            if "source" not in columns:  # before reports were tied to their recording
                self._connection.execute(
                    "ALTER TABLE outputs ADD COLUMN source TEXT NOT NULL DEFAULT ''"
                )
        if version < 2:  # one recording ('' for none) -> every recording it holds
            rows = self._connection.execute("SELECT path, source FROM outputs").fetchall()
            for path, source in rows:
                held = json.dumps([source] if source else [])
                self._connection.execute(
                    "UPDATE outputs SET source = ? WHERE path = ?", (held, path)
                )
        if version < SCHEMA_VERSION:
            self._connection.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")

    def close(self) -> None:
        self._connection.close()

    @contextmanager
    def transaction(self) -> Iterator[Connection]:
        """Everything inside is written together, or not at all."""
        connection = self._connection
        connection.execute("BEGIN IMMEDIATE")
        try:
            yield connection
        except BaseException:
            connection.rollback()
            raise
        connection.commit()

    # -- the index ----------------------------------------------------------------------
    def add_session(
        self, path: Path, person: str, started: float, profile: str, kept: tuple[str, ...]
    ) -> None:
        with self.transaction() as db:
            db.execute(
                "INSERT OR REPLACE INTO sessions VALUES (?, ?, ?, NULL, ?, ?)",
                (str(path), person, started, profile, json.dumps(list(kept))),
            )

    def end_session(self, path: Path, length_s: float) -> None:
        with self.transaction() as db:
            db.execute("UPDATE sessions SET length_s = ? WHERE path = ?", (length_s, str(path)))

    def sessions(self, person: str | None = None) -> list[SessionEntry]:
        """The index, oldest first; only ``person``'s when given."""
        sql = "SELECT path, person, started, length_s, profile, kept FROM sessions"
        rows = (
            self._connection.execute(sql + " WHERE person = ? ORDER BY started", (person,))
            if person is not None
            else self._connection.execute(sql + " ORDER BY started")
        )
        return [
            SessionEntry(Path(path), who, started, length, profile, tuple(json.loads(kept)))
            for path, who, started, length, profile, kept in rows.fetchall()
        ]

    def session_at(self, path: Path) -> SessionEntry | None:
        """The index's entry of the recording at ``path`` (resolved), or None."""
        row = self._connection.execute(
            "SELECT path, person, started, length_s, profile, kept FROM sessions WHERE path = ?",
            (str(path),),
        ).fetchone()
        if row is None:
            return None
        where, person, started, length, profile, kept = row
        return SessionEntry(Path(where), person, started, length, profile, tuple(json.loads(kept)))

    def forget_session(self, path: Path) -> None:
        with self.transaction() as db:
            db.execute("DELETE FROM sessions WHERE path = ?", (str(path),))

    def add_output(
        self, path: Path, person: str, kind: str, made: float, sources: Sequence[Path]
    ) -> None:
        """Notes ``path``, written about ``person``, holding the recordings ``sources``."""
        held = json.dumps([str(source) for source in sources])
        with self.transaction() as db:
            db.execute(
                "INSERT OR REPLACE INTO outputs VALUES (?, ?, ?, ?, ?)",
                (str(path), person, kind, made, held),
            )

    def is_output(self, path: Path) -> bool:
        """Whether vest wrote ``path`` (a report, an export) for this site."""
        row = self._connection.execute(
            "SELECT 1 FROM outputs WHERE path = ?", (str(path),)
        ).fetchone()
        return row is not None

    def outputs_holding(self, source: Path) -> list[Path]:
        """What was written in the clear that holds the recording ``source`` (its report,
        a progress report or an export of its person, a conversion of it)."""
        rows = self._connection.execute("SELECT path, source FROM outputs ORDER BY made").fetchall()
        return [Path(path) for path, held in rows if str(source) in json.loads(held or "[]")]

    def forget_output(self, path: Path) -> None:
        with self.transaction() as db:
            db.execute("DELETE FROM outputs WHERE path = ?", (str(path),))

    def outputs(self, person: str) -> list[tuple[Path, str]]:
        """What was written in the clear about ``person``: (path, kind: report or export)."""
        rows = self._connection.execute(
            "SELECT path, kind FROM outputs WHERE person = ? ORDER BY made", (person,)
        ).fetchall()
        return [(Path(path), kind) for path, kind in rows]

    def people(self) -> list[str]:
        rows = self._connection.execute(
            "SELECT DISTINCT person FROM sessions WHERE person != '' ORDER BY person"
        ).fetchall()
        return [person for (person,) in rows]

    # -- erasures -----------------------------------------------------------------------
    def begin_erasing(self, person: str, since: float) -> None:
        with self.transaction() as db:
            db.execute("INSERT OR IGNORE INTO erasing VALUES (?, ?)", (person, since))

    def unfinished_erasures(self) -> list[str]:
        rows = self._connection.execute("SELECT person FROM erasing ORDER BY since").fetchall()
        return [person for (person,) in rows]

    def finish_erasing(self, person: str, audit: tuple[float, str, str]) -> None:
        """Forgets every row naming ``person`` and writes the audit line ``audit`` (at,
        who, what), in one transaction."""
        at, who, what = audit
        with self.transaction() as db:
            db.execute("DELETE FROM sessions WHERE person = ?", (person,))
            db.execute("DELETE FROM outputs WHERE person = ?", (person,))
            db.execute("DELETE FROM erasing WHERE person = ?", (person,))
            self._append(db, at, who, "erase", person, what)

    # -- the audit trail ----------------------------------------------------------------
    def audit(self, at: float, who: str, action: str, person: str, what: str) -> None:
        """Appends one line: ``who`` (the system user) did ``action`` (record, replay,
        report, export, erase, purge, rekey, seal...) about ``person`` ('' for none)."""
        with self.transaction() as db:
            self._append(db, at, who, action, person, what)

    @staticmethod
    def _append(db: Connection, at: float, who: str, action: str, person: str, what: str) -> None:
        last = db.execute("SELECT chain FROM audit ORDER BY seq DESC LIMIT 1").fetchone()
        link = _link(last[0] if last else FIRST_LINK, at, who, action, person, what)
        db.execute(
            "INSERT INTO audit (at, who, action, person, what, chain) VALUES (?, ?, ?, ?, ?, ?)",
            (at, who, action, person, what, link),
        )

    def audit_lines(self) -> list[AuditLine]:
        """Every line, oldest first, each checked against the chain."""
        lines: list[AuditLine] = []
        previous, intact = FIRST_LINK, True
        for seq, at, who, action, person, what, chain in self._connection.execute(
            "SELECT seq, at, who, action, person, what, chain FROM audit ORDER BY seq"
        ).fetchall():
            intact = intact and chain == _link(previous, at, who, action, person, what)
            lines.append(AuditLine(seq, at, who, action, person, what, chain, intact))
            previous = chain
        return lines


def _link(previous: str, at: float, who: str, action: str, person: str, what: str) -> str:
    text = json.dumps([previous, repr(at), who, action, person, what])
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()
