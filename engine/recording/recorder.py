"""Recording a session as it runs (``vest run --record FILE``), without costing the tick.

A reader of the session stream (:mod:`engine.session.events`): the scheduler's thread
only turns each event into a row (a tree version, a node's status, a blackboard change,
and every other event as itself, its message of :mod:`engine.session.codec`) and puts
it on a bounded queue; a writer thread beside it stores the rows in the SQLite file
(:mod:`engine.recording.session_file`, encrypted with the site's key) in batches. It
reads the consent gate's kept exit (:mod:`engine.privacy.consent_gate`), so only what the
person consented to reaches it; the file says what was left out (``meta``: ``person``,
``kept``, ``left_out``).
Should the disk fall so far behind that the queue fills, notes are dropped and counted,
never waited for: the robot's ticks come first, and the file says how many were lost.
"""

from __future__ import annotations

import hashlib
import logging
from pathlib import Path
from typing import Any

from engine.clock import Clock
from engine.privacy.sealed_sqlite import Error
from engine.privacy.site_data import SiteKey
from engine.recording.session_file import create
from engine.session.codec import encode
from engine.session.events import KeyChanged, NodeStatus, SessionEvent, TreeStarted
from engine.session.handoff import Handoff
from engine.session.json_values import json_text

log = logging.getLogger(__name__)
CAPACITY = 200_000
"""Notes the queue holds before it drops (minutes of a busy session's changes)."""
Row = tuple[str, tuple[Any, ...]]


class SessionRecorder:
    """Records one session into ``path``, encrypted with ``key``: a reader of the consent
    gate's kept exit (``on_event``); times are clock seconds minus ``start_s``."""

    def __init__(
        self,
        path: Path,
        clock: Clock,
        key: SiteKey,
        *,
        capacity: int = CAPACITY,
    ) -> None:
        self.path = path
        self.clock = clock
        self.start_s = clock.now()
        self._connection: Any = create(path, key)
        self._seq = 0  # the order of the session's events across tables
        self.length_s: float | None = None
        """How long the session lasted (seconds), once closed."""
        self.stopped_why: str | None = None
        """Why the recording stopped before the session ended (a full disk), or None."""
        self._handoff = Handoff("recorder", self._write, capacity=capacity)
        self._handoff.start()

    @property
    def dropped(self) -> int:
        """Changes lost because the disk fell behind (never waited for)."""
        return self._handoff.dropped

    # -- what the session is ------------------------------------------------------------
    def describe(self, **facts: str) -> None:
        """Facts about the session kept in ``meta`` (robot config, profile, started)."""
        for key, value in facts.items():
            self._note("INSERT OR REPLACE INTO meta VALUES (?, ?)", (key, value))

    def begin(self, start_s: float) -> None:
        """Times count from ``start_s`` (clock seconds)."""
        self.start_s = start_s

    def _at(self, t_s: float) -> float:
        return round(t_s - self.start_s, 6)

    # -- as the robot runs (the scheduler's thread) ---------------------------------------
    def on_event(self, event: SessionEvent) -> None:
        if isinstance(event, NodeStatus):
            self._note(
                "INSERT INTO statuses VALUES (?, ?, ?, ?, ?, ?, ?)",
                (
                    self._at(event.t_s),
                    event.tree,
                    event.version,
                    event.tick,
                    event.node,
                    event.status,
                    event.feedback,
                ),
            )
        elif isinstance(event, KeyChanged):
            self._note(
                "INSERT INTO blackboard VALUES (?, ?, ?, ?, ?)",
                (self._at(event.t_s), event.key, event.text, event.event, self._next()),
            )
        elif isinstance(event, TreeStarted):
            self._record_tree(event)
        else:  # the session's account: the event itself (engine/session/codec.py)
            self._note(
                "INSERT INTO events VALUES (?, ?, ?, ?, ?)",
                (
                    self._at(event.t_s),
                    event.kind,
                    str(getattr(event, "tree", "")),
                    json_text(encode(event, self.start_s)),
                    self._next(),
                ),
            )

    def _next(self) -> int:
        self._seq += 1
        return self._seq

    def _record_tree(self, event: TreeStarted) -> None:
        self._note(
            "INSERT INTO trees VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
            (
                event.tree,
                event.version,
                self._at(event.t_s),
                str(event.file),
                _digest(event.files),
                event.rate_hz,
                _source(event.file),
                event.dot,
            ),
        )
        for node in event.nodes:
            self._note(
                "INSERT INTO nodes VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    event.tree,
                    event.version,
                    node.index,
                    node.path,
                    node.type,
                    node.label,
                    node.depth,
                    node.words,
                ),
            )

    def _note(self, sql: str, row: tuple[Any, ...]) -> None:
        self._handoff.put((sql, row))

    # -- the writer thread ----------------------------------------------------------------
    def _write(self, batch: list[Row]) -> bool:
        """One batch, one commit; False (no more) when the disk refuses."""
        connection = self._connection
        assert connection is not None
        try:
            for item in batch:
                connection.execute(*item)
            connection.commit()
        except Error as error:  # a full disk: the robot goes on, the record stops
            log.error("recording %s stopped: %s", self.path, error)
            self.stopped_why = str(error)
            return False
        return True

    def close(self) -> None:
        """Write what is still queued, how long the session was and what was lost."""
        if self._connection is None:
            return
        self.length_s = self._at(self.clock.now())
        self.describe(duration_s=f"{self.length_s:.3f}", dropped=str(self.dropped))
        self._handoff.close()  # what is queued is written (unless the writer stopped)
        self._connection.close()
        self._connection = None
        if self.dropped:
            log.warning(
                "recording %s lost %d changes (the disk fell behind)", self.path, self.dropped
            )


def _digest(files: tuple[Path, ...]) -> str:
    """SHA-256 over the tree's files (its own and its subtrees'), in order."""
    digest = hashlib.sha256()
    for path in files:
        try:
            digest.update(path.read_bytes())
        except OSError:
            digest.update(b"<unreadable>")
    return digest.hexdigest()


def _source(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return ""
