"""What the live view shows, kept current as the robot runs: one data model for live and
replay (:mod:`engine.view.sources`).

The scheduler's thread tells the hub what changed (a node's status after a tick, a
committed blackboard write, a service call, a scenario event; every second the tick and
bus statistics). The hub keeps the present state for a page that connects, and puts each
change on every connected page's bounded queue. A page that cannot keep up loses changes
(its queue overflows, and it is told to fetch the state again), never a tick: nothing here
waits for a browser.
"""

from __future__ import annotations

import contextlib
import queue
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import asdict
from typing import Any

from engine.blackboard.catalogue import VARIABLES_PREFIX, KeyCatalogue
from engine.clock import Clock
from engine.drivers.device_stats import DeviceStats
from engine.loader.tree_drawing import dot_source
from engine.recording.recorder import tick_moment
from engine.recording.session_file import ChangedKeys, as_json
from engine.runtime.scheduler import RunningTree
from engine.runtime.tree_watch import TreeWatch, WatchedTree
from engine.scenario.scenario_file import ScenarioEvent
from engine.services.actions import ActionRecord

Change = dict[str, Any]
QUEUE_CHANGES = 5000
"""Changes a page may be behind before it is told to start again from the state."""
RECENT_ACTIONS = 100
STATS_EVERY_S = 1.0


class Subscription:
    """One connected page: its queue of changes, and whether it overflowed."""

    def __init__(self, capacity: int) -> None:
        self.changes: queue.Queue[Change | None] = queue.Queue(maxsize=capacity)
        self.overflowed = False

    def offer(self, change: Change) -> None:
        try:
            self.changes.put_nowait(change)
        except queue.Full:
            self.overflowed = True

    def close(self) -> None:
        """Wake the page's sender so it ends (after what is queued)."""
        with contextlib.suppress(queue.Full):  # a full queue wakes its sender anyway
            self.changes.put_nowait(None)


class ViewHub:
    """The live state of one robot, and the pages watching it. Times are clock seconds
    minus ``start_s`` (the session's start, as in the timeline and in recordings)."""

    def __init__(
        self,
        clock: Clock,
        catalogue: KeyCatalogue,
        *,
        device_stats: Callable[[], dict[str, DeviceStats]] | None = None,
        capacity: int = QUEUE_CHANGES,
    ) -> None:
        self.clock = clock
        self.catalogue = catalogue
        self.start_s = clock.now()
        self.device_stats = device_stats
        self.capacity = capacity
        self._lock = threading.Lock()
        self._watch = TreeWatch()
        self._pages: list[Subscription] = []
        self._trees: dict[str, Change] = {}
        self._dots: dict[tuple[str, int], str] = {}
        self._statuses: dict[str, dict[int, Change]] = {}
        self._keys: dict[str, Change] = {}
        self._changed = ChangedKeys(catalogue)
        self._actions: deque[Change] = deque(maxlen=RECENT_ACTIONS)
        self._world: deque[Change] = deque(maxlen=RECENT_ACTIONS)
        self._stats: Change = {"kind": "stats", "at": 0.0, "trees": {}, "devices": {}}
        self._running: list[RunningTree] = []
        self._next_stats_s = 0.0

    # -- the scheduler's thread -------------------------------------------------------------
    def begin(self, start_s: float, trees: list[RunningTree]) -> None:
        self.start_s = start_s
        self._running = trees
        for tree in trees:
            self._tree(self._watch.watch(tree))

    def _at(self) -> float:
        return round(self.clock.now() - self.start_s, 3)

    def _tree(self, watched: WatchedTree) -> None:
        change: Change = {
            "kind": "tree",
            "at": self._at(),
            "tree": watched.name,
            "version": watched.version,
            "rate_hz": watched.definition.rate_hz,
            "file": str(watched.definition.path),
            "nodes": [asdict(node) for node in watched.info],
        }
        with self._lock:
            self._dots[(watched.name, watched.version)] = dot_source(watched.definition)
            self._trees[watched.name] = change
            self._statuses[watched.name] = {}
        self._publish(change)

    def tree_ticked(self, tree: RunningTree) -> None:
        watched, new, changes = self._watch.look(tree)
        if new:
            self._tree(watched)
        if not changes:
            return
        at = round(tick_moment(tree, self.start_s), 3)
        for index, status, feedback in changes:
            change = {
                "kind": "status",
                "at": at,
                "tree": tree.name,
                "version": watched.version,
                "node": index,
                "status": status,
                "feedback": feedback,
            }
            with self._lock:
                self._statuses.setdefault(tree.name, {})[index] = change
            self._publish(change)

    def blackboard_write(self, key: str, value: Any) -> None:
        news = self._changed.news(key, value)
        if news is None:
            return
        text, event = news
        spec = self.catalogue.lookup(key)
        writer = "trees" if key.startswith(VARIABLES_PREFIX) else (spec.writer if spec else "")
        change = {
            "kind": "key",
            "at": self._at(),
            "key": key,
            "value": text,
            "event": event,
            "writer": writer,
        }
        with self._lock:
            self._keys[key] = change
        self._publish(change)

    def action(self, record: ActionRecord) -> None:
        change = {
            "kind": "action",
            "at": round(record.t - self.start_s, 3),
            "tree": record.tree,
            "action": record.action,
            "args": as_json(record.args),
            "error": None,
        }
        with self._lock:
            self._actions.append(change)
        self._publish(change)

    def failed(self, record: ActionRecord, error: BaseException) -> None:
        change = {
            "kind": "action_failed",
            "at": round(record.t - self.start_s, 3),
            "tree": record.tree,
            "action": record.action,
            "error": record.error,
        }
        self._publish(change)

    def world(self, at_s: float, event: ScenarioEvent) -> None:
        change = {"kind": "world", "at": round(at_s - self.start_s, 3), "what": event.describe()}
        with self._lock:
            self._world.append(change)
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
        change = {"kind": "stats", "at": self._at(), "trees": trees, "devices": devices}
        with self._lock:
            self._stats = change
        self._publish(change)

    def _publish(self, change: Change) -> None:
        with self._lock:
            pages = list(self._pages)
        for page in pages:
            page.offer(change)

    # -- the pages' threads -----------------------------------------------------------------
    def subscribe(self) -> Subscription:
        page = Subscription(self.capacity)
        with self._lock:
            self._pages.append(page)
        return page

    def unsubscribe(self, page: Subscription) -> None:
        with self._lock:
            if page in self._pages:
                self._pages.remove(page)

    def close(self) -> None:
        """Tell every page the session ended."""
        self._publish({"kind": "end", "at": self._at()})
        with self._lock:
            pages, self._pages = list(self._pages), []
        for page in pages:
            page.close()

    def snapshot(self) -> Change:
        """The present state: every tree with its nodes' statuses, the blackboard, the
        recent actions, the statistics."""
        with self._lock:
            return {
                "now": self._at(),
                "trees": [
                    {**tree, "statuses": list(self._statuses.get(name, {}).values())}
                    for name, tree in sorted(self._trees.items())
                ],
                "keys": sorted(self._keys.values(), key=lambda change: change["key"]),
                "actions": list(self._actions),
                "world": list(self._world),
                "stats": self._stats,
            }

    def dot(self, tree: str, version: int) -> str | None:
        """The Graphviz source of a tree version, as ``vest render`` draws it."""
        with self._lock:
            return self._dots.get((tree, version))
