"""One voice at a time: the speaker, the face LEDs and each joint are resources.

A tree's service call holds the resources it uses while its job runs. When another tree
asks for a resource that is held:

- a tree of higher priority interrupts the holder: the holder's tree is halted cleanly
  (its jobs cancelled, its joints sent to rest) and the call goes through;
- a tree of the same or lower priority waits for its turn up to its ``wait_for_turn_s``
  and then lets the action go (the node fails with the reason), or lets it go at once.

Every interruption, wait and yield is published on the session stream as a
:class:`~engine.session.events.TurnTaken`: the timeline prints who yielded to whom, the
recording keeps it, the live view shows it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from engine.blackboard.catalogue import NOTHING, Carries
from engine.clock import Clock
from engine.errors import ServiceError
from engine.services.jobs import ImmediateJob, Job
from engine.session.events import TurnKind, TurnTaken
from engine.session.stream import SessionStream

SPEAKER = "speaker"
FACE_LEDS = "face LEDs"


def joint_resource(joint: str) -> str:
    """The resource of one joint: ``left_arm joint``."""
    return f"{joint} joint"


class TurnYieldedError(ServiceError):
    """An action was let go because another tree had the resource it needs."""


@dataclass
class Turn:
    """A tree holding a resource while ``job`` runs."""

    tree: str
    priority: int
    job: Job


class Turns:
    """Who holds each resource now, and the rules for taking turns.

    ``interrupt(tree, by, resource)`` halts a tree by name because tree ``by`` takes
    ``resource`` from it (the robot's: halt cleanly, joints to rest).
    """

    def __init__(
        self,
        clock: Clock,
        *,
        stream: SessionStream | None = None,
        interrupt: Callable[[str, str, str], None] = lambda tree, by, resource: None,
    ) -> None:
        self.clock = clock
        self.stream = stream
        self.interrupt = interrupt
        self._held: dict[str, Turn] = {}
        self._in_line: list[WaitingJob] = []
        """Actions waiting for their turn: a free resource goes to the highest of them."""

    def holder(self, resource: str, tree: str) -> Turn | None:
        """Another tree's turn on ``resource`` that is still running, or None."""
        turn = self._held.get(resource)
        if turn is None or turn.tree == tree or turn.job.done():
            return None
        return turn

    def blocking(
        self, resources: Sequence[str], tree: str, priority: int
    ) -> tuple[str, Turn] | None:
        """The first of ``resources`` held by another tree of the same or a higher
        priority, with that tree's turn; None when ``tree`` may go ahead."""
        for resource in resources:
            turn = self.holder(resource, tree)
            if turn is not None and turn.priority >= priority:
                return resource, turn
        return None

    def waiting_ahead(
        self, resources: Sequence[str], tree: str, priority: int
    ) -> tuple[str, Turn] | None:
        """(resource, its place in line) of another tree of higher priority that waits
        for one of ``resources``, or None: a free resource goes to the highest waiting
        tree, not to a lower one that happens to ask first."""
        self._in_line = [job for job in self._in_line if job.waiting]
        for job in self._in_line:
            shared = [r for r in resources if r in job.resources]
            if shared and job.tree != tree and job.priority > priority:
                return shared[0], job.place
        return None

    def line_up(self, job: WaitingJob) -> None:
        self._in_line.append(job)

    def take(self, resources: Sequence[str], tree: str, priority: int) -> None:
        """Interrupt every lower-priority tree holding one of ``resources``."""
        for resource in resources:
            turn = self.holder(resource, tree)
            if turn is not None and turn.priority < priority:
                self.tell(tree, "interrupts", resource, turn.tree)
                # the resource is the newcomer's before the halted tree comes to rest, so
                # that tree does not send it home just before the newcomer's own move
                self._held[resource] = Turn(tree, priority, ImmediateJob())
                self.interrupt(turn.tree, tree, resource)

    def hold(self, resources: Sequence[str], tree: str, priority: int, job: Job) -> None:
        for resource in resources:
            self._held[resource] = Turn(tree, priority, job)

    def last_user(self, resource: str) -> str | None:
        """The tree whose action on ``resource`` started last (its job may be over)."""
        turn = self._held.get(resource)
        return turn.tree if turn is not None else None

    def tell(
        self,
        tree: str,
        turn: TurnKind,
        resource: str,
        other: str,
        what: str = "",
        carries: Carries = NOTHING,
    ) -> None:
        """Publish one turn event (``tree`` interrupts, waits for, yields... ``what``, made
        from ``carries`` of a person)."""
        if self.stream is not None:
            now = self.clock.now()
            self.stream.publish(TurnTaken(now, tree, turn, resource, other, what, carries))


class WaitingJob:
    """An action waiting for its turn: started once nothing of the same or a higher
    priority holds its resources, or let go (failed with :class:`TurnYieldedError`) when
    ``deadline_s`` passes first."""

    def __init__(
        self,
        turns: Turns,
        start: Callable[[], Job],
        resources: Sequence[str],
        tree: str,
        priority: int,
        deadline_s: float,
        what: str,
        carries: Carries = NOTHING,
    ) -> None:
        self._turns = turns
        self._carries = carries
        self._start = start
        self.resources = resources
        self.tree = tree
        self.priority = priority
        self._deadline_s = deadline_s
        self._what = what
        self._job: Job | None = None
        self._error: BaseException | None = None
        self.place = Turn(tree, priority, ImmediateJob())
        """Its place in line, as a turn a lower tree gives way to."""
        turns.line_up(self)

    @property
    def waiting(self) -> bool:
        """Still waiting for its turn (asking :meth:`done` may start it)."""
        return self._job is None and self._error is None

    def done(self) -> bool:
        if self._job is not None:
            return self._job.done()
        if self._error is not None:
            return True
        turns = self._turns
        blocked = turns.blocking(self.resources, self.tree, self.priority)
        ahead = turns.waiting_ahead(self.resources, self.tree, self.priority)
        if blocked is None and ahead is None:
            turns.take(self.resources, self.tree, self.priority)
            job = self._job = self._start()
            if not (job.done() and job.error() is not None):
                turns.hold(self.resources, self.tree, self.priority, job)
            return job.done()
        if turns.clock.now() >= self._deadline_s:
            place = blocked if blocked is not None else ahead
            assert place is not None
            resource, turn = place
            self._error = let_go(turns, self.tree, self._what, resource, turn, self._carries)
            return True
        return False

    def error(self) -> BaseException | None:
        if self._job is not None:
            return self._job.error()
        return self._error

    def result(self) -> Any:
        return self._job.result() if self._job is not None else None

    def cancel(self) -> None:
        if self._job is not None:
            self._job.cancel()
        elif self._error is None:
            self._error = TurnYieldedError("stopped while waiting for its turn")


def let_go(
    turns: Turns, tree: str, what: str, resource: str, turn: Turn, carries: Carries = NOTHING
) -> TurnYieldedError:
    """Tell that ``tree`` lets ``what`` (made from ``carries`` of a person) go because
    ``turn`` has ``resource``; the error its node fails with."""
    turns.tell(tree, "yields", resource, turn.tree, what, carries)
    return TurnYieldedError(f"{turn.tree} has the {resource} (priority {turn.priority})")
