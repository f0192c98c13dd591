"""Recording a session as it runs (``vest run --record FILE``), without costing the tick.

The scheduler's thread only notes what changed (a node's status after a tick, a committed
blackboard write, a service call) and puts it on a bounded queue; a writer thread beside
it stores the notes in the SQLite file (:mod:`engine.recording.session_file`) in batches.
Should the disk fall so far behind that the queue fills, notes are dropped and counted,
never waited for: the robot's ticks come first, and the file says how many were lost.
"""

from __future__ import annotations

import hashlib
import json
import logging
import queue
import sqlite3
import threading
from pathlib import Path
from typing import Any

from engine.blackboard.catalogue import KeyCatalogue
from engine.clock import Clock
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_drawing import dot_source
from engine.recording.session_file import ChangedKeys, create
from engine.runtime.scheduler import RunningTree
from engine.runtime.tree_watch import TreeWatch, WatchedTree
from engine.scenario.scenario_file import ScenarioEvent
from engine.services.actions import ActionRecord

log = logging.getLogger(__name__)
CAPACITY = 200_000
"""Notes the queue holds before it drops (minutes of a busy session's changes)."""
Row = tuple[str, tuple[Any, ...]]


class SessionRecorder:
    """Records one session into ``path``; times are clock seconds minus ``start_s``."""

    def __init__(
        self, path: Path, clock: Clock, catalogue: KeyCatalogue, *, capacity: int = CAPACITY
    ) -> None:
        self.path = path
        self.clock = clock
        self.start_s = clock.now()
        self.dropped = 0
        self._broken = False
        self._connection: sqlite3.Connection | None = create(path)
        self._queue: queue.Queue[Row | None] = queue.Queue(maxsize=capacity)
        self._watch = TreeWatch()
        self._changed = ChangedKeys(catalogue)
        self._thread = threading.Thread(target=self._write, name="recorder", daemon=True)
        self._thread.start()

    # -- what the session is ------------------------------------------------------------
    def describe(self, **facts: str) -> None:
        """Facts about the session kept in ``meta`` (robot config, profile, started)."""
        for key, value in facts.items():
            self._note("INSERT OR REPLACE INTO meta VALUES (?, ?)", (key, value))

    def begin(self, start_s: float, trees: list[RunningTree]) -> None:
        """Times count from ``start_s`` (clock seconds); record every tree as it is now."""
        self.start_s = start_s
        for tree in trees:
            self._record_tree(self._watch.watch(tree))

    def _at(self) -> float:
        return round(self.clock.now() - self.start_s, 6)

    def _record_tree(self, watched: WatchedTree) -> None:
        definition = watched.definition
        self._note(
            "INSERT INTO trees VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
            (
                watched.name,
                watched.version,
                self._at(),
                str(definition.path),
                _digest(definition),
                definition.rate_hz,
                _source(definition.path),
                dot_source(definition),
            ),
        )
        for node in watched.info:
            self._note(
                "INSERT INTO nodes VALUES (?, ?, ?, ?, ?, ?, ?)",
                (
                    watched.name,
                    watched.version,
                    node.index,
                    node.path,
                    node.type,
                    node.label,
                    node.depth,
                ),
            )

    # -- as the robot runs (the scheduler's thread) ---------------------------------------
    def tree_ticked(self, tree: RunningTree) -> None:
        """After ``tree`` ticked: note each node whose status or feedback changed."""
        watched, new, changes = self._watch.look(tree)
        if new:  # hot-reloaded
            self._record_tree(watched)
        at = tick_moment(tree, self.start_s)
        for index, status, feedback in changes:
            self._note(
                "INSERT INTO statuses VALUES (?, ?, ?, ?, ?, ?, ?)",
                (at, tree.name, watched.version, watched.ticks, index, status, feedback),
            )

    def blackboard_write(self, key: str, value: Any) -> None:
        """A blackboard watcher: a committed write (or event). A state key's write that
        does not change its value (a sensor polled 20 times a second) is not noted."""
        news = self._changed.news(key, value)
        if news is None:
            return
        text, event = news
        self._note("INSERT INTO blackboard VALUES (?, ?, ?, ?)", (self._at(), key, text, event))

    def action(self, record: ActionRecord) -> None:
        """An action log listener: a service call."""
        args = json.dumps(record.args, default=str)
        self._note(
            "INSERT INTO actions VALUES (?, ?, ?, ?, ?)",
            (round(record.t - self.start_s, 6), record.tree, record.action, args, None),
        )

    def failed(self, record: ActionRecord, error: BaseException) -> None:
        """An action log failure listener: the call turned out to have failed."""
        self._note(
            "UPDATE actions SET error = ? WHERE rowid = (SELECT max(rowid) FROM actions "
            "WHERE at_s = ? AND tree = ? AND action = ?)",
            (record.error, round(record.t - self.start_s, 6), record.tree, record.action),
        )

    def world(self, at_s: float, event: ScenarioEvent) -> None:
        """A scenario event, as the timeline hears it."""
        self._note(
            "INSERT INTO world VALUES (?, ?, ?)",
            (round(at_s - self.start_s, 6), event.kind, event.describe()),
        )

    def _note(self, sql: str, row: tuple[Any, ...]) -> None:
        if self._broken:
            return
        try:
            self._queue.put_nowait((sql, row))
        except queue.Full:
            self.dropped += 1

    # -- the writer thread ----------------------------------------------------------------
    def _write(self) -> None:
        connection = self._connection
        assert connection is not None
        stopping = False
        while not stopping:
            batch = [self._queue.get()]
            while len(batch) < 5000:  # everything already waiting, then one commit
                try:
                    batch.append(self._queue.get_nowait())
                except queue.Empty:
                    break
            try:
                for item in batch:
                    if item is None:
                        stopping = True
                        continue
                    connection.execute(*item)
                connection.commit()
            except sqlite3.Error as error:  # a full disk: the robot goes on, the record stops
                log.error("recording %s stopped: %s", self.path, error)
                self._broken = True
                return

    def close(self) -> None:
        """Write what is still queued, how long the session was and what was lost."""
        if self._connection is None:
            return
        self.describe(duration_s=f"{self._at():.3f}", dropped=str(self.dropped))
        if not self._broken:  # a writer that stopped reads no more: nothing to wait for
            self._queue.put(None)
            self._thread.join()
        self._connection.close()
        self._connection = None
        if self.dropped:
            log.warning(
                "recording %s lost %d changes (the disk fell behind)", self.path, self.dropped
            )


def tick_moment(tree: RunningTree, start_s: float) -> float:
    """When the tick that just ended was due (s since ``start_s``): its statuses hold from
    then, so a moment shows a tree's actions and the statuses that led to them together."""
    return round(tree.next_deadline_s - start_s, 6)


def _digest(definition: TreeDefinition) -> str:
    """SHA-256 over the tree's files (its own and its subtrees'), in order."""
    digest = hashlib.sha256()
    for path in definition.files or [definition.path]:
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
