"""The robot's blackboard: staged writes committed between ticks.

Each robot owns its :class:`Blackboard` and the keys in it (py_trees' own blackboard is one
dictionary for the whole process: two robots, or two test harnesses, in one process would
see each other's keys; vest's nodes do not use it). Threads that produce data (pollers,
the speech recognizer, the IoT client) call :meth:`Blackboard.stage` or
:meth:`Blackboard.stage_event`; the scheduler calls :meth:`Blackboard.commit` between
ticks, so a tick never sees half an update. Tree nodes read with :meth:`get` and write
during their tick with :meth:`set`.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from typing import Any

from engine.blackboard.catalogue import (
    NOTHING,
    VARIABLES_PREFIX,
    Carries,
    KeyCatalogue,
    captures_of,
)
from engine.blackboard.events import EventLog
from engine.clock import Clock

_log = logging.getLogger(__name__)

Watcher = Callable[[str, Any], None]


class Blackboard:
    """Staging and committing writes, event logs, and when each key last changed.

    Times are the injected clock's seconds.
    """

    def __init__(self, catalogue: KeyCatalogue, clock: Clock) -> None:
        self.catalogue = catalogue
        self.clock = clock
        self._pending: list[tuple[str, Any, bool]] = []
        self._lock = threading.Lock()
        self._updated_s: dict[str, float] = {}
        self._values: dict[str, Any] = {}
        """Every committed key's value: this robot's alone."""
        self.watchers: list[Watcher] = []
        """Called as (key, value) for every committed write (debug views, the timeline).

        A watcher that raises is logged the first time and counted (:meth:`watcher_failures`);
        the commit goes on for the other writes and watchers."""
        self._watcher_failures: dict[int, int] = {}  # by id(): a watcher may be unhashable
        self.wake_keys: frozenset[str] = frozenset()
        """Keys some tree wakes on (``wake_on:``): a change to one calls :attr:`on_wake`."""
        self.on_wake: Callable[[], None] | None = None
        """Called (from the writing thread) when a wake key is staged with a new value,
        gets an event, or is written by a tree: the scheduler steps at once."""
        self._last_staged: dict[str, Any] = {}
        self._changed: set[str] = set()
        self._committing = False
        self._carries: dict[str, Carries] = {}
        """What of a person each ``/vars/`` key's value was made from (its writer said)."""

    # -- producers (any thread) ---------------------------------------------------------
    def stage(self, key: str, value: Any) -> None:
        """Queue ``key = value`` for the next commit."""
        with self._lock:
            self._pending.append((key, value, False))
            wakes = key in self.wake_keys and not _same(self._last_staged.get(key, _NONE), value)
            if wakes:
                self._last_staged[key] = value
        if wakes and self.on_wake is not None:
            self.on_wake()

    def stage_event(self, key: str, value: Any) -> None:
        """Queue one event on ``key`` for the next commit."""
        with self._lock:
            self._pending.append((key, value, True))
        if key in self.wake_keys and self.on_wake is not None:
            self.on_wake()

    def take_changed(self) -> set[str]:
        """The wake keys that changed since the last call (the scheduler's thread)."""
        changed, self._changed = self._changed, set()
        return changed

    # -- the scheduler's thread ---------------------------------------------------------
    def commit(self) -> int:
        """Apply every staged write, in order; returns how many there were."""
        with self._lock:
            pending, self._pending = self._pending, []
        self._committing = True  # the scheduler reads what changed right after: no wake-up
        try:
            for key, value, is_event in pending:
                if is_event:
                    self._append_event(key, value)
                else:
                    self._write(key, value)
                for watcher in self.watchers:
                    self._tell(watcher, key, value)
        finally:
            self._committing = False
        return len(pending)

    def _tell(self, watcher: Watcher, key: str, value: Any) -> None:
        """Tell one watcher of a write; a watcher (a view, the timeline) that fails must
        not lose the writes after it nor stop the robot, so it is logged once and counted."""
        try:
            watcher(key, value)
        except Exception as error:
            count = self._watcher_failures.get(id(watcher), 0) + 1
            self._watcher_failures[id(watcher)] = count
            if count == 1:
                _log.error(
                    "blackboard watcher %r failed on %s: %s: %s (failure 1; later ones are "
                    "counted, not logged)",
                    watcher,
                    key,
                    type(error).__name__,
                    error,
                )

    def watcher_failures(self, watcher: Watcher) -> int:
        """How many times ``watcher`` has raised while told of a commit."""
        return self._watcher_failures.get(id(watcher), 0)

    def set(self, key: str, value: Any, *, carries: Carries = NOTHING) -> None:
        """Write now (a tree node during its tick, or a test). Event keys get an event.
        ``carries``: what of a person the value was made from (a ``/vars/`` key holding
        what was heard carries words; see :func:`carried_by`)."""
        if key.startswith(VARIABLES_PREFIX):
            if carries:
                self._carries[key] = carries
            else:
                self._carries.pop(key, None)
        spec = self.catalogue.lookup(key)
        if spec is not None and spec.kind == "event":
            self._append_event(key, value)
        else:
            self._write(key, value)

    def emit(self, key: str, value: Any) -> None:
        """Add an event to ``key`` now."""
        self._append_event(key, value)

    def get(self, key: str, default: Any = None) -> Any:
        return self._values.get(key, default)

    def carried_by(self, keys: Iterable[str]) -> Carries:
        """What of a person the values of ``keys`` are or were made from, together: a
        sensor's readings, what was heard, and what a tree's variable was made from."""
        found: set[str] = set()
        for key in keys:
            found |= self._carries.get(key, NOTHING) or captures_of(key)
        return frozenset(found) if found else NOTHING

    def event_log(self, key: str) -> EventLog:
        log = self._values.get(key)
        return log if isinstance(log, EventLog) else EventLog()

    def updated_s(self, key: str) -> float | None:
        """Clock time of the last write to ``key``, or None if never written."""
        return self._updated_s.get(key)

    def snapshot(self) -> dict[str, Any]:
        """A copy of every key and value, for debug views and recordings."""
        return dict(self._values)

    def reset(self) -> None:
        """Forget every key and pending write (a fresh robot)."""
        with self._lock:
            self._pending.clear()
            self._last_staged.clear()
        self._changed.clear()
        self._updated_s.clear()
        self._values.clear()
        self._carries.clear()

    def _write(self, key: str, value: Any) -> None:
        if key in self.wake_keys and not _same(self._values.get(key, _NONE), value):
            self._changed.add(key)
            if self.on_wake is not None and not self._committing:  # a tree wrote it
                self.on_wake()
        self._values[key] = value
        self._updated_s[key] = self.clock.now()

    def _append_event(self, key: str, value: Any) -> None:
        now = self.clock.now()
        self._values[key] = self.event_log(key).appended(value, now)
        self._updated_s[key] = now
        if key in self.wake_keys:
            self._changed.add(key)
            if self.on_wake is not None and not self._committing:
                self.on_wake()


_NONE = object()
"""A key with no value yet."""


def _same(old: Any, new: Any) -> bool:
    """Whether a key's new value is its old one (a value that cannot say counts as new)."""
    if old is new:
        return True
    if isinstance(old, float) and isinstance(new, float) and old != old and new != new:
        return True  # NaN, read again: no reading still
    try:
        return bool(old == new)
    except Exception:  # an array's comparison, say
        return False
