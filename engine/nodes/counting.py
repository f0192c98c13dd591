"""Counting and timing what a person does, without programming: "twice within 4 seconds",
"held for 3 seconds" (and, in :mod:`engine.nodes.decorators`, "not again for 10 seconds":
``Cooldown``).

Both wrap a question (a condition: a pat, an event, a check of a reading) and measure on
the engine clock, never the wall clock. A question about something that lasts (a
``Check`` that the force is above 5 N) counts once each time it becomes true, however
long it stays true; a question about events (``OnTouch``, ``OnEvent``) counts each event.
"""

from __future__ import annotations

from collections import deque
from types import SimpleNamespace
from typing import Any

import py_trees
from py_trees.common import Status

from engine.clock import Clock
from engine.nodes.context import TreeContext
from engine.nodes.spec import NodeType
from engine.values.params import REQUIRED, Integer, Number, Param

A_WHILE_S = Number(0.1, 86_400.0, "s")
"""A time to count within or hold for: at least a tenth of a second (0 could never be met)."""


class TimesWithin(py_trees.decorators.Decorator):
    """SUCCESS once the child's answer came true ``times`` times within ``within_s``
    seconds (then the count starts again); FAILURE until then; RUNNING while the child
    runs."""

    def __init__(self, name: str, child: Any, times: int, within_s: float, clock: Clock) -> None:
        super().__init__(name=name, child=child)
        self.times = times
        self.within_s = within_s
        self.clock = clock
        self.counted: deque[float] = deque()
        """When each counted answer came (clock seconds), the oldest first."""
        self._was_true = False
        self._each_event = hasattr(child, "events")  # an event reader: every event counts

    def update(self) -> Status:
        status = self.decorated.status
        if status == Status.RUNNING:
            return status
        now_s = self.clock.now()
        true = status == Status.SUCCESS
        if true and (self._each_event or not self._was_true):
            self.counted.append(now_s)
        self._was_true = true
        while self.counted and now_s - self.counted[0] > self.within_s:
            self.counted.popleft()  # too long ago to count with the next
        if len(self.counted) >= self.times:
            self.counted.clear()
            self.feedback_message = f"{self.times} times within {self.within_s:g} s"
            return Status.SUCCESS
        self.feedback_message = (
            f"{len(self.counted)} of {self.times} within {self.within_s:g} s"
            if self.counted
            else ""
        )
        return Status.FAILURE


class HeldFor(py_trees.decorators.Decorator):
    """SUCCESS once the child's answer has stayed true for ``seconds`` (once per hold: it
    must become false and true again to count again); RUNNING while it is true but not
    yet for that long (the tree keeps watching the clock); FAILURE while it is false."""

    def __init__(self, name: str, child: Any, seconds: float, clock: Clock) -> None:
        super().__init__(name=name, child=child)
        self.seconds = seconds
        self.clock = clock
        self.since_s: float | None = None
        """When the answer became true (clock seconds); None while it is false."""
        self.counted = False

    def terminate(self, new_status: Status) -> None:
        """Halted while it watched a hold (a higher branch or tree took over): the hold
        starts again. (A new round's reset, after it answered, keeps what it knows.)"""
        if new_status == Status.INVALID and self.status == Status.RUNNING:
            self.since_s, self.counted = None, False

    def update(self) -> Status:
        if self.decorated.status != Status.SUCCESS:
            self.since_s, self.counted = None, False
            self.feedback_message = ""
            return Status.FAILURE
        now_s = self.clock.now()
        if self.since_s is None:
            self.since_s = now_s
        held_s = now_s - self.since_s
        if self.counted:
            self.feedback_message = f"still held ({held_s:.1f} s): let go to count again"
            return Status.FAILURE
        if held_s + 1e-9 >= self.seconds:
            self.counted = True
            self.feedback_message = f"held for {self.seconds:g} s"
            return Status.SUCCESS
        self.feedback_message = f"held {held_s:.1f} of {self.seconds:g} s"
        return Status.RUNNING


def _times_within(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return TimesWithin(name, children[0], args.times, args.within_s, ctx.clock)


def _held_for(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return HeldFor(name, children[0], args.seconds, ctx.clock)


COUNTING = (
    NodeType(
        "TimesWithin",
        "decorator",
        """N times within T seconds: the question under it must come true that many times
        (times) within that many seconds (within s), as in "patted twice within 4 seconds".

        A reading that stays true (a squeeze) counts once until it is false again; each
        event (a pat, a word) counts. SUCCESS when the count is reached (then it starts
        again); FAILURE until then; RUNNING while the node under it runs.""",
        (
            Param("times", Integer(minimum=2, maximum=100), REQUIRED, "how many times"),
            Param("within_s", A_WHILE_S, REQUIRED, "within how many seconds"),
        ),
        _times_within,
    ),
    NodeType(
        "HeldFor",
        "decorator",
        """Held for T seconds: the question under it must stay true that long (seconds), as
        in "a hug held for 3 seconds".

        SUCCESS once when it has been true that long (it must be false again before it
        counts again); RUNNING while it is true but not yet that long; FAILURE while it
        is false.""",
        (Param("seconds", A_WHILE_S, REQUIRED, "for how many seconds"),),
        _held_for,
    ),
)
