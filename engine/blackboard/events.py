"""Events on the blackboard: things that happen once (a wave, an utterance, a command).

An event key holds an :class:`EventLog`, an immutable snapshot of the most recent events,
each with a sequence number. A tree node remembers the last sequence number it handled,
so it reacts to each event exactly once however many ticks the log stays on the board,
and two trees can each react to the same event.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

EVENT_LOG_LENGTH = 32


@dataclass(frozen=True, slots=True)
class Event:
    """One event: ``seq`` counts from 1 per key; ``at_s`` is the clock time it was committed."""

    seq: int
    value: Any
    at_s: float


@dataclass(frozen=True, slots=True)
class EventLog:
    """The last :data:`EVENT_LOG_LENGTH` events of one key, oldest first."""

    events: tuple[Event, ...] = ()

    @property
    def last_seq(self) -> int:
        """Sequence number of the newest event (0 when none has happened)."""
        return self.events[-1].seq if self.events else 0

    @property
    def latest(self) -> Event | None:
        return self.events[-1] if self.events else None

    def appended(self, value: Any, at_s: float) -> EventLog:
        """A new log with ``value`` added as the next event."""
        event = Event(self.last_seq + 1, value, at_s)
        return EventLog((*self.events, event)[-EVENT_LOG_LENGTH:])

    def after(self, seq: int) -> tuple[Event, ...]:
        """Events newer than ``seq``, oldest first (a slow reader may have missed some)."""
        if seq >= self.last_seq:
            return ()
        return tuple(event for event in self.events if event.seq > seq)
