"""Reading a session recording back: the trees' statuses and the blackboard at any moment.

:class:`Recording` answers "what was the robot doing at 12.5 s?" from the file alone (the
tree files may have changed since): each tree as it ran then, each node's last status at
or before that moment, each key's last value.
"""

from __future__ import annotations

import json
import math
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from engine.errors import ConfigError
from engine.privacy.sealed_sqlite import Connection, Error
from engine.privacy.site_data import SiteKey
from engine.recording.session_file import TABLES, open_for_reading, whole_number
from engine.session.codec import EventError, decode
from engine.session.events import ActionEnded, ActionStarted, NodeInfo, SessionEvent, WorldEvent

STATUS_MARKS = {"SUCCESS": "ok", "FAILURE": "no", "RUNNING": "..", "INVALID": "  "}
"""How a status reads in the terminal: success, failure, running, not ticked."""


@dataclass(frozen=True)
class RecordedTree:
    """One version of a tree as it ran from ``at_s`` on."""

    name: str
    version: int
    at_s: float
    rate_hz: float
    digest: str
    nodes: tuple[NodeInfo, ...]
    file: Path


@dataclass(frozen=True)
class NodeState:
    status: str
    feedback: str
    since_s: float


@dataclass(frozen=True)
class KeyState:
    value: Any
    since_s: float


@dataclass(frozen=True)
class RecordedAction:
    """A service call: when, by which tree, what; how it ended (``outcome``: done,
    failed, cut, or None when the session ended first or the format did not say) and
    when (``ended_s``), and why it failed (``error``)."""

    at_s: float
    tree: str
    action: str
    args: dict[str, Any]
    error: str | None
    outcome: str | None = None
    ended_s: float | None = None
    why: str = ""
    seq: int = 0
    """Its place in the session's order of events (format 2; 0 in format 1)."""
    ended_seq: int = 0
    """Its end's place in that order."""

    @property
    def cut(self) -> bool:
        return self.outcome == "cut"


class Recording:
    """A recording opened for reading (:func:`Recording.open`)."""

    def __init__(self, path: Path, connection: Connection, *, plain: bool = False) -> None:
        self.path = path
        self.plain = plain
        """Made before recordings were sealed: readable by anyone (``vest data seal``)."""
        self._connection = connection
        self._lock = threading.Lock()  # the replay view asks from several threads
        self.meta = dict(self._rows("SELECT key, value FROM meta"))
        self.trees = self._read_trees()

    def _rows(self, sql: str, parameters: tuple[Any, ...] = ()) -> list[Any]:
        """ConfigError naming the file when it turns out damaged."""
        with self._lock:
            try:
                rows: list[Any] = self._connection.execute(sql, parameters).fetchall()
                return rows
            except (Error, OverflowError) as error:
                raise ConfigError(f"{self.path}: a damaged recording ({error})") from None

    @classmethod
    def open(cls, path: Path, key: SiteKey | None) -> Recording:
        """The recording at ``path``, decrypted with the site's ``key``; ConfigError naming
        the file when it is not a recording this vest reads (or not with this key; None:
        only a plain recording, made before they were sealed, can be read)."""
        opened = open_for_reading(path, key)
        return cls(path, opened.connection, plain=opened.plain)

    def close(self) -> None:
        with self._lock:
            self._connection.close()

    @property
    def format(self) -> int:
        return int(self.meta["format"])

    @property
    def cut_short(self) -> str | None:
        """Why the recording is not whole, or None: a recording that was never finished
        (the disk filled, or vest was killed) has no ``duration_s``; one that lost changes
        on the way says how many."""
        if "duration_s" not in self.meta:
            return (
                f"{self.path}: the recording was cut short at {self.duration_s:.2f} s (it was "
                "never finished: the disk filled, or vest was stopped hard, or it is still "
                "being recorded); what came after is not in it"
            )
        dropped = whole_number(self.meta.get("dropped", "0"))
        if dropped is None:
            raise ConfigError(f"{self.path}: a damaged recording (its count of lost changes)")
        if dropped > 0:
            return f"{self.path}: the recording lost {dropped} changes (the disk fell behind)"
        return None

    @property
    def duration_s(self) -> float:
        """How long the session ran (the last thing recorded, if it was cut off)."""
        if "duration_s" in self.meta:
            try:
                duration = float(self.meta["duration_s"])
            except ValueError:
                duration = math.nan
            if not math.isfinite(duration) or duration < 0:
                raise ConfigError(f"{self.path}: a damaged recording (duration {duration!r})")
            return duration
        last = [
            self._rows(f"SELECT max(at_s) FROM {table}")[0][0]
            for table in ("statuses", "blackboard", "actions")
        ]
        end_s = max((float(t) for t in last if t is not None), default=0.0)
        if not math.isfinite(end_s) or end_s < 0:
            raise ConfigError(f"{self.path}: a damaged recording (a change at {end_s} s)")
        return end_s

    def _read_trees(self) -> list[RecordedTree]:
        nodes: dict[tuple[str, int], list[NodeInfo]] = {}
        words = "words" if self.format >= 4 else "''"  # not kept before format 4
        for tree, version, index, path, kind, label, depth, said in self._rows(
            f"SELECT tree, version, node, path, type, label, depth, {words} FROM nodes "
            "ORDER BY tree, version, node"
        ):
            node = NodeInfo(index, path, kind, label, depth, said)
            nodes.setdefault((tree, version), []).append(node)
        return [
            RecordedTree(
                name,
                version,
                at_s,
                rate_hz,
                digest,
                tuple(nodes.get((name, version), [])),
                Path(file),
            )
            for name, version, at_s, rate_hz, digest, file in self._rows(
                "SELECT tree, version, at_s, rate_hz, digest, file FROM trees "
                "ORDER BY tree, version"
            )
        ]

    def trees_at(self, at_s: float) -> list[RecordedTree]:
        """Each tree as it ran at ``at_s`` (its latest version by then; the first before)."""
        chosen: dict[str, RecordedTree] = {}
        for tree in self.trees:
            if tree.name not in chosen or tree.at_s <= at_s:
                chosen[tree.name] = tree
        return [chosen[name] for name in sorted(chosen)]

    def statuses_at(self, at_s: float) -> dict[tuple[str, int, int], NodeState]:
        """(tree, version, node) -> its last status at or before ``at_s``."""
        rows = self._rows(
            "SELECT tree, version, node, status, feedback, at_s FROM statuses "
            "WHERE rowid IN (SELECT max(rowid) FROM statuses WHERE at_s <= ? "
            "GROUP BY tree, version, node)",
            (at_s,),
        )
        return {(t, v, n): NodeState(s, f, a) for t, v, n, s, f, a in rows}

    def blackboard_at(self, at_s: float) -> dict[str, KeyState]:
        """Each key's last value (an event key: its last event) at or before ``at_s``."""
        rows = self._rows(
            "SELECT key, value, at_s FROM blackboard WHERE rowid IN "
            "(SELECT max(rowid) FROM blackboard WHERE at_s <= ? GROUP BY key)",
            (at_s,),
        )
        return {key: KeyState(self.json(value), at) for key, value, at in rows}

    def dot(self, tree: str, version: int) -> str | None:
        """The Graphviz source of a tree version, as it was drawn when recorded."""
        rows = self._rows("SELECT dot FROM trees WHERE tree = ? AND version = ?", (tree, version))
        return str(rows[0][0]) if rows else None

    def moments(self) -> list[float]:
        """Every moment something changed (a status, a key, an action), in order: the
        steps of a replay."""
        actions = (
            "SELECT at_s FROM events WHERE kind = 'action'"
            if self.format >= 3
            else "SELECT at_s FROM actions"
        )
        rows = self._rows(
            f"SELECT at_s FROM statuses UNION SELECT at_s FROM blackboard UNION {actions} "
            "ORDER BY 1"
        )
        return [at for (at,) in rows]

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]:
        """Each (moment, status, feedback) of one node, in order."""
        rows = self._rows(
            "SELECT at_s, status, feedback FROM statuses WHERE tree = ? AND version = ? "
            "AND node = ? ORDER BY rowid",
            (tree, version, node),
        )
        return [(at, status, feedback) for at, status, feedback in rows]

    def world(self) -> list[tuple[float, str, str]]:
        """(moment, kind, description) of what happened around a simulated robot (its
        scenario's events); none for a robot in a real room."""
        if self.format >= 3:
            return [
                (e.t_s, e.scenario_event, e.description)
                for e in self.session_events()
                if isinstance(e, WorldEvent)
            ]
        rows = self._rows("SELECT at_s, kind, description FROM world ORDER BY rowid")
        return [(at, kind, description) for at, kind, description in rows]

    def table(self, name: str) -> list[dict[str, Any]]:
        """Every row of the recording's table ``name`` (one of :data:`TABLES` or
        ``events``), each as {column: value}, in the order written (for an export)."""
        if name not in (*TABLES, "events"):
            raise ValueError(f"no table {name!r} in a recording")
        if name == "events" and self.format < 2:
            return []
        columns = [row[1] for row in self._rows(f"PRAGMA table_info({name})")]
        rows = self._rows(f"SELECT {', '.join(columns)} FROM {name} ORDER BY rowid")
        return [dict(zip(columns, row, strict=True)) for row in rows]

    def ordered_rows(self, table: str, columns: str, until_s: float) -> list[Any]:
        """Rows of ``table`` up to ``until_s`` with their order across tables (format 2's
        ``seq``; 0 in format 1) last; ConfigError for a row whose time or order is not a
        number (a damaged recording)."""
        seq = "coalesce(seq, 0)" if self.format >= 2 else "0"
        rows = self._rows(
            f"SELECT {columns}, {seq} FROM {table} WHERE at_s <= ? ORDER BY rowid", (until_s,)
        )
        for row in rows:
            if not _numbers(row[0], row[-1]):
                raise ConfigError(f"{self.path}: a damaged recording ({table} at {row[0]!r})")
        return rows

    def json(self, text: Any) -> Any:
        """A value the recording keeps as JSON; ConfigError naming the file when it is not."""
        try:
            return json.loads(text)
        except (TypeError, ValueError, RecursionError):
            raise ConfigError(
                f"{self.path}: a damaged recording (not JSON: {text!r:.60})"
            ) from None

    def key_history(self, key: str) -> list[tuple[float, Any]]:
        """Each (moment, value) ``key`` took (each event, for an event key), in order."""
        rows = self._rows("SELECT at_s, value FROM blackboard WHERE key = ? ORDER BY rowid", (key,))
        return [(at, self.json(value)) for at, value in rows]

    def is_event(self, key: str) -> bool:
        """Whether ``key`` was recorded as an event key."""
        return bool(self._rows("SELECT max(event) FROM blackboard WHERE key = ?", (key,))[0][0])

    def keys_like(self, pattern: str) -> list[str]:
        """The keys written that match an SQL LIKE ``pattern`` (``/devices/%/ok``)."""
        rows = self._rows(
            "SELECT DISTINCT key FROM blackboard WHERE key LIKE ? ORDER BY key", (pattern,)
        )
        return [key for (key,) in rows]

    def feedback_containing(self, text: str) -> list[tuple[float, str]]:
        """(moment, feedback) of each node status change whose feedback holds ``text``."""
        rows = self._rows(
            "SELECT at_s, feedback FROM statuses WHERE instr(feedback, ?) > 0 ORDER BY rowid",
            (text,),
        )
        return [(at, feedback) for at, feedback in rows]

    def actions(self, until_s: float | None = None) -> list[RecordedAction]:
        """The service calls, in order (up to ``until_s`` when given)."""
        until = float("inf") if until_s is None else until_s
        if self.format >= 3:
            return _paired(self._ordered_events(), until)
        if self.format < 2:
            rows = self._rows(
                "SELECT at_s, tree, action, args, error, NULL, NULL, NULL, NULL, NULL FROM actions "
                "WHERE at_s <= ? ORDER BY rowid",
                (until,),
            )
        else:
            rows = self._rows(
                "SELECT at_s, tree, action, args, error, outcome, ended_s, why, seq, ended_seq "
                "FROM actions "
                "WHERE at_s <= ? ORDER BY rowid",
                (until,),
            )
        actions = []
        for at, tree, action, text, error, outcome, ended_s, why, seq, ended_seq in rows:
            args = self.json(text)
            if not isinstance(args, dict) or not _numbers(at, seq or 0, ended_seq or 0):
                raise ConfigError(f"{self.path}: a damaged recording (an action at {at!r})")
            actions.append(
                _action(at, tree, action, args, error, outcome, ended_s, why, seq, ended_seq)
            )
        return actions

    def session_events(self, until_s: float | None = None) -> list[SessionEvent]:
        """The session's events as they were told (format 3 on), up to ``until_s``, in
        order; a row that is not an event this vest reads is left out, not guessed."""
        return [event for _, event in self._ordered_events(until_s)]

    def _ordered_events(self, until_s: float | None = None) -> list[tuple[int, SessionEvent]]:
        """(order, event) of each event the ``events`` table keeps as itself (format 3)."""
        found = []
        for _, seq, _, _, message in self.events(until_s):
            try:
                found.append((seq, decode(message)))
            except EventError:
                continue  # a damaged row, or a kind a later vest tells
        return found

    def events(
        self, until_s: float | None = None
    ) -> list[tuple[float, int, str, str, dict[str, Any]]]:
        """(moment, order, kind, tree, fields) of each row of the ``events`` table: every
        event of the session as its message (format 3), or the fields of its turns,
        safety, presses, pauses, not understood, not listened to and reloads (format 2);
        none in format 1, which did not keep them."""
        if self.format < 2:
            return []
        rows = self._rows(
            "SELECT at_s, seq, kind, tree, data FROM events WHERE at_s <= ? ORDER BY rowid",
            (float("inf") if until_s is None else until_s,),
        )
        found = []
        for at, seq, kind, tree, data in rows:
            fields = self.json(data)
            if not isinstance(fields, dict) or not _numbers(at, seq or 0):
                raise ConfigError(f"{self.path}: a damaged recording (an event at {at!r} s)")
            found.append((at, seq or 0, str(kind), str(tree), fields))
        return found


def _numbers(*values: Any) -> bool:
    """Whether every value is a real number (a time, an order), as recordings keep them."""
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def _paired(events: list[tuple[int, SessionEvent]], until_s: float) -> list[RecordedAction]:
    """The actions begun by ``until_s``, each with how it ended (whenever that was)."""
    ended = {e.action_id: (seq, e) for seq, e in events if isinstance(e, ActionEnded)}
    actions = []
    for seq, e in events:
        if not isinstance(e, ActionStarted) or e.t_s > until_s:
            continue
        end_seq, end = ended.get(e.action_id, (0, None))
        if end is None:
            actions.append(RecordedAction(e.t_s, e.tree, e.action, e.args, None, seq=seq))
            continue
        error = end.why if end.outcome == "failed" else None
        actions.append(
            RecordedAction(
                e.t_s, e.tree, e.action, e.args, error, end.outcome, end.t_s, end.why, seq, end_seq
            )
        )
    return actions


def _action(
    at: float,
    tree: str,
    action: str,
    args: dict[str, Any],
    error: str | None,
    outcome: str | None,
    ended_s: float | None,
    why: str | None,
    seq: int | None,
    ended_seq: int | None,
) -> RecordedAction:
    if outcome is None and error is not None:  # format 1 kept only the error
        outcome = "failed"
    return RecordedAction(
        at,
        tree,
        action,
        args,
        error,
        outcome,
        ended_s,
        why or error or "",
        seq or 0,
        ended_seq or seq or 0,
    )
