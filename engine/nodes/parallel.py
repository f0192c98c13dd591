"""The Parallel composite: children side by side, each allowed to finish.

py_trees' own Parallel fails the moment one child fails and halts the others. For a social
robot that is the wrong default: with the face LEDs unplugged, SetLed fails at once, the
hug's Parallel fails and cuts "I love hugs!" short, and the next tick starts it again
(21 times in a second). Here a failing child never cuts the others short: the robot still
says what it meant to say, once, and the Parallel reports the failure when every child has
finished (BehaviorTree.CPP's ParallelAll does the same).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Literal

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import Status


class Parallel(py_trees.composites.Composite):
    """Tick every unfinished child each tick until all have finished.

    ``succeed_when="all"``: SUCCESS when every child succeeded; FAILURE when every child
    has finished and at least one failed (the feedback names them); RUNNING before.
    ``succeed_when="one"``: SUCCESS as soon as one child succeeds: the children after it
    are not ticked in that tick, those still running are halted (as BehaviorTree.CPP's
    Parallel with success_count 1); FAILURE when every child failed. ``synchronise``: a
    child that succeeded is not ticked again in this round (with ``False`` it is, so a
    condition can change its mind).
    """

    def __init__(
        self,
        name: str,
        children: Sequence[Behaviour],
        *,
        succeed_when: Literal["all", "one"] = "all",
        synchronise: bool = True,
    ) -> None:
        super().__init__(name=name, children=list(children))
        self.succeed_when = succeed_when
        self.synchronise = synchronise

    def tick(self) -> Iterator[Behaviour]:
        if self.status != Status.RUNNING:
            for child in self.children:
                if child.status != Status.INVALID:
                    child.stop(Status.INVALID)
            self.current_child = None
            self.initialise()
        if not self.children:
            self.stop(Status.SUCCESS)
            yield self
            return
        for child in self.children:
            if child.status == Status.FAILURE:
                continue  # finished this round; it waits for its siblings
            if child.status == Status.SUCCESS and self.synchronise:
                continue
            yield from child.tick()
            if self.succeed_when == "one" and child.status == Status.SUCCESS:
                break  # decided: the children after it are not started only to be halted
        new_status = self._outcome()
        self.current_child = self.children[-1]
        if new_status != Status.RUNNING:
            self.stop(new_status)  # halts children still running (succeed_when: one)
        self.status = new_status
        yield self

    def stop(self, new_status: Status = Status.INVALID) -> None:
        """Halt every child still running (succeed_when: one, or a pre-emption)."""
        for child in self.children:
            if child.status == Status.RUNNING:
                child.stop(Status.INVALID)
        super().stop(new_status)

    def _outcome(self) -> Status:
        statuses = [child.status for child in self.children]
        if self.succeed_when == "one" and Status.SUCCESS in statuses:
            self.feedback_message = ""
            return Status.SUCCESS
        if Status.RUNNING in statuses:
            return Status.RUNNING
        failed = [child.name for child in self.children if child.status == Status.FAILURE]
        if self.succeed_when == "all" and not failed:
            self.feedback_message = ""
            return Status.SUCCESS
        self.feedback_message = "failed: " + ", ".join(failed)
        return Status.FAILURE
