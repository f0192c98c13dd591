"""What the live view shows, kept current as the robot runs: one data model for live and
replay (:mod:`engine.view.replay_source`).

A reader of the session stream: the scheduler's thread tells the hub each event (a tree
version, a node's status after a tick, a blackboard change, and everything told in words:
actions and how they ended, turns, safety, presses, what was heard; every second the tick
and bus statistics come from its hook). The hub keeps the present state for a page that
connects, and publishes each change once on a bounded broadcast every page reads. A page
that cannot keep up loses changes (it is told to fetch the state again), never a tick:
nothing here waits for a browser, and publishing costs the same for one page or many.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from dataclasses import asdict
from typing import Any

from engine.clock import Clock
from engine.drivers.device_stats import DeviceStats
from engine.runtime.scheduler import RunningTree
from engine.session.events import KeyChanged, NodeStatus, SessionEvent, TreeStarted
from engine.session.sentences import event_line, tone
from engine.web.broadcast import Broadcast

Change = dict[str, Any]
QUEUE_CHANGES = 5000
"""Changes a page may be behind before it is told to start again from the state."""
RECENT_HAPPENINGS = 100
STATS_EVERY_S = 1.0


def happened(event: SessionEvent, start_s: float) -> Change | None:
    """``event`` as a line of the page's "what happened" (None: not told in words)."""
    line = event_line(event)
    if line is None:
        return None
    who, what = line
    return {
        "kind": "happened",
        "at": round(event.t_s - start_s, 3),
        "who": who,
        "what": what,
        "tone": tone(event),
    }


class ViewHub:
    """The live state of one robot, and the pages watching it: a session reader
    (``on_event``). Times are clock seconds minus ``start_s`` (the session's start, as in
    the timeline and in recordings)."""

    def __init__(
        self,
        clock: Clock,
        *,
        device_stats: Callable[[], dict[str, DeviceStats]] | None = None,
        capacity: int = QUEUE_CHANGES,
    ) -> None:
        self.clock = clock
        self.start_s = clock.now()
        self.device_stats = device_stats
        self.capacity = capacity
        self._lock = threading.Lock()
        self.changes: Broadcast[Change] = Broadcast(clock, capacity)
        """Every change, for the pages' streams (the state to start from: :meth:`snapshot`)."""
        self._trees: dict[str, Change] = {}
        self._dots: dict[tuple[str, int], str] = {}
        self._statuses: dict[str, dict[int, Change]] = {}
        self._keys: dict[str, Change] = {}
        self._happened: deque[Change] = deque(maxlen=RECENT_HAPPENINGS)
        self._stats: Change = {"kind": "stats", "at": 0.0, "trees": {}, "devices": {}}
        self._running: list[RunningTree] = []
        self._next_stats_s = 0.0

    # -- the scheduler's thread -------------------------------------------------------------
    def begin(self, start_s: float, trees: list[RunningTree]) -> None:
        """Times count from ``start_s`` (clock seconds); ``trees``' statistics are sent."""
        self.start_s = start_s
        self._running = trees

    def _at(self, t_s: float) -> float:
        return round(t_s - self.start_s, 3)

    def on_event(self, event: SessionEvent) -> None:
        if isinstance(event, NodeStatus):
            change = {
                "kind": "status",
                "at": self._at(event.t_s),
                "tree": event.tree,
                "version": event.version,
                "node": event.node,
                "status": event.status,
                "feedback": event.feedback,
            }
            with self._lock:
                self._statuses.setdefault(event.tree, {})[event.node] = change
        elif isinstance(event, KeyChanged):
            change = {
                "kind": "key",
                "at": self._at(event.t_s),
                "key": event.key,
                "value": event.text,
                "event": event.event,
                "writer": event.writer,
            }
            with self._lock:
                self._keys[event.key] = change
        elif isinstance(event, TreeStarted):
            change = {
                "kind": "tree",
                "at": self._at(event.t_s),
                "tree": event.tree,
                "version": event.version,
                "rate_hz": event.rate_hz,
                "priority": event.priority,
                "file": str(event.file),
                "nodes": [asdict(node) for node in event.nodes],
            }
            with self._lock:
                self._dots[(event.tree, event.version)] = event.dot
                self._trees[event.tree] = change
                self._statuses[event.tree] = {}
        else:
            told = happened(event, self.start_s)
            if told is None:
                return
            change = told
            with self._lock:
                self._happened.append(change)
        self._publish(change)

    def stats_hook(self, now_s: float) -> None:
        """A scheduler hook: every second, the trees' tick statistics and the buses'."""
        if now_s < self._next_stats_s:
            return
        self._next_stats_s = now_s + STATS_EVERY_S
        trees = {tree.name: tree.stats.summary() for tree in self._running}
        devices: dict[str, Any] = {}
        if self.device_stats is not None:
            devices = {name: asdict(stats) for name, stats in self.device_stats().items()}
        change = {"kind": "stats", "at": self._at(now_s), "trees": trees, "devices": devices}
        with self._lock:
            self._stats = change
        self._publish(change)

    def _publish(self, change: Change) -> None:
        self.changes.publish(change)  # once, however many pages watch

    def close(self) -> None:
        """Tell every page the session ended."""
        self._publish({"kind": "end", "at": self._at(self.clock.now())})
        self.changes.close()

    def snapshot(self) -> Change:
        """The present state: every tree with its nodes' statuses, the blackboard, what
        happened lately (in words), the statistics."""
        with self._lock:
            return {
                "now": self._at(self.clock.now()),
                "trees": [
                    {**tree, "statuses": list(self._statuses.get(name, {}).values())}
                    for name, tree in sorted(self._trees.items())
                ],
                "keys": sorted(self._keys.values(), key=lambda change: change["key"]),
                "happened": list(self._happened),
                "stats": self._stats,
            }

    def dot(self, tree: str, version: int) -> str | None:
        """The Graphviz source of a tree version, as ``vest render`` draws it."""
        with self._lock:
            return self._dots.get((tree, version))
