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
    def __init__(
        self, observer: SessionObserver, kinds: frozenset[str] | None, relay: bool
    ) -> None:
        self.observer = observer
        self.kinds = kinds
        self.relay = relay
        self.failures = 0


class SessionStream:
    """Where a session's events go; ``start_s`` is the clock time the session started
    (the first tick), from which readers count. A stream may have branches
    (:meth:`branch`): streams of their own, fed by a relay subscribed here (the consent
    gate), that count from the same start."""

    def __init__(self, clock: Clock, *, source: SessionStream | None = None) -> None:
        self.clock = clock
        self._start_s = clock.now()
        self._source = source
        self._subscriptions: list[_Subscription] = []
        self._branches: list[SessionStream] = []
        self._wanted: set[str] = set()
        self._everything = False

    @property
    def start_s(self) -> float:
        return self._source.start_s if self._source is not None else self._start_s

    @start_s.setter
    def start_s(self, value: float) -> None:
        self._start_s = value

    def branch(self) -> SessionStream:
        """A stream of its own that counts from this one's start, fed by a relay
        subscribed here (``subscribe(relay, relay=True)``): this stream wants what the
        branch's readers want."""
        branch = SessionStream(self.clock, source=self)
        self._branches.append(branch)
        return branch

    def subscribe(
        self,
        observer: SessionObserver,
        kinds: Iterable[str] | None = None,
        *,
        relay: bool = False,
    ) -> None:
        """Tell ``observer`` every event (or those of ``kinds``) from now on. A ``relay``
        is told every event, but wants only what the branches' readers want."""
        chosen = None if kinds is None else frozenset(kinds)
        self._subscriptions.append(_Subscription(observer, chosen, relay))
        self._remember_wanted()

    def _remember_wanted(self) -> None:
        readers = [s for s in self._subscriptions if not s.relay]
        self._everything = any(s.kinds is None for s in readers)
        self._wanted = set().union(*(s.kinds or () for s in readers))

    def wants(self, kind: str) -> bool:
        """Whether any reader (here or on a branch) wants events of ``kind`` (a producer
        may skip costly work)."""
        if self._everything or kind in self._wanted:
            return True
        return any(branch.wants(kind) for branch in self._branches)

    @property
    def readers(self) -> list[SessionObserver]:
        """Who is subscribed here, relays included (an architecture test asks)."""
        return [s.observer for s in self._subscriptions]

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
