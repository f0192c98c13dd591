"""The session event stream: producers publish, every reader observes the same events.

One observer interface (:class:`SessionObserver`, like BehaviorTree.CPP's
``StatusChangeLogger``), subscribed once. Events are published on the scheduler's thread
(producers in other threads stage on the blackboard, whose commit turns them into events),
so readers see them in one order. A reader must not block: the recorder and the live view
queue what they are told and lose updates when they fall behind, never a tick. A reader
that raises is logged once, counted, and told the next events as usual.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from typing import Protocol, TypeVar

from engine.clock import Clock
from engine.session.events import SessionEvent

_log = logging.getLogger("vest.session")
E = TypeVar("E")


class SessionObserver(Protocol):
    """A reader of the session: told every event it asked for, in order."""

    def on_event(self, event: SessionEvent) -> None: ...


class _Subscription:
    def __init__(self, observer: SessionObserver, kinds: frozenset[str] | None) -> None:
        self.observer = observer
        self.kinds = kinds
        self.failures = 0


class SessionStream:
    """Where a session's events go; ``start_s`` is the clock time the session started
    (the first tick), from which readers count."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self.start_s = clock.now()
        self._subscriptions: list[_Subscription] = []
        self._wanted: set[str] = set()
        self._everything = False

    def subscribe(self, observer: SessionObserver, kinds: Iterable[str] | None = None) -> None:
        """Tell ``observer`` every event (or those of ``kinds``) from now on."""
        chosen = None if kinds is None else frozenset(kinds)
        self._subscriptions.append(_Subscription(observer, chosen))
        self._remember_wanted()

    def unsubscribe(self, observer: SessionObserver) -> None:
        self._subscriptions = [s for s in self._subscriptions if s.observer is not observer]
        self._remember_wanted()

    def _remember_wanted(self) -> None:
        self._everything = any(s.kinds is None for s in self._subscriptions)
        self._wanted = set().union(*(s.kinds or () for s in self._subscriptions))

    def wants(self, kind: str) -> bool:
        """Whether any reader wants events of ``kind`` (a producer may skip costly work)."""
        return self._everything or kind in self._wanted

    def publish(self, event: SessionEvent) -> None:
        """Tell every reader that wants it, in the order they subscribed."""
        for subscription in self._subscriptions:
            kinds = subscription.kinds
            if kinds is not None and event.kind not in kinds:
                continue
            try:
                subscription.observer.on_event(event)
            except Exception as error:  # a view or recorder must never stop the robot
                subscription.failures += 1
                if subscription.failures == 1:
                    _log.error(
                        "session reader %r failed on a %s event: %s: %s (later failures are "
                        "counted, not logged)",
                        subscription.observer,
                        event.kind,
                        type(error).__name__,
                        error,
                    )

    def failures(self, observer: SessionObserver) -> int:
        """How many events ``observer`` failed on."""
        return sum(s.failures for s in self._subscriptions if s.observer is observer)

    def since_start(self, t_s: float) -> float:
        """Clock seconds ``t_s`` as seconds since the session started."""
        return t_s - self.start_s


class EventCollector:
    """A reader that keeps every event it is told (tests, reruns, benchmarks)."""

    def __init__(self, on_event: Callable[[SessionEvent], None] | None = None) -> None:
        self.events: list[SessionEvent] = []
        self._then = on_event

    def on_event(self, event: SessionEvent) -> None:
        self.events.append(event)
        if self._then is not None:
            self._then(event)

    def of(self, kind: type[E]) -> list[E]:
        """The events of one type, in order."""
        return [event for event in self.events if isinstance(event, kind)]
