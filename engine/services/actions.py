"""What trees ask of services, recorded: the robot's actions on the session stream.

:class:`TreeActions` is the one door from a tree's nodes to the services. Each call
becomes an :class:`ActionRecord` (time, tree, action, args) kept by the :class:`ActionLog`,
which publishes it as an :class:`~engine.session.events.ActionStarted` and, once the job
is seen to end, its :class:`~engine.session.events.ActionEnded`: done, failed (the
service could not, the safety envelope refused or stopped it) or cut short (its tree was
halted: interrupted by a higher one, paused, reloaded, stopped).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from engine.blackboard.catalogue import NOTHING, Carries
from engine.clock import Clock
from engine.services.interfaces import Services
from engine.services.jobs import ImmediateJob, Job
from engine.services.turns import (
    FACE_LEDS,
    SPEAKER,
    Turn,
    Turns,
    TurnYieldedError,
    WaitingJob,
    joint_resource,
    let_go,
)
from engine.session.events import ActionEnded, ActionStarted, Outcome
from engine.session.stream import SessionStream

_log = logging.getLogger("vest.actions")

SPOKEN_OVER = "a person spoke over it"
"""The :attr:`TreeActions.stop_reason` of a tree halted because a person spoke over it."""


@dataclass
class ActionRecord:
    """One service call: ``t`` in clock seconds, the tree, the action name and its arguments.

    ``outcome`` is None while the call is under way, then ``done``, ``failed`` or ``cut``;
    ``error`` says why it failed (the action was asked for but not done).
    """

    t: float
    tree: str
    action: str
    args: dict[str, Any]
    error: str | None = None
    outcome: Outcome | None = None
    action_id: int = 0
    carries: Carries = NOTHING
    """What of a person ``args`` were made from."""

    @property
    def failed(self) -> bool:
        return self.error is not None

    @property
    def cut(self) -> bool:
        return self.outcome == "cut"


@dataclass
class ActionLog:
    """Keeps every record and publishes each call and its outcome on ``stream``."""

    stream: SessionStream | None = None
    records: list[ActionRecord] = field(default_factory=list)

    def add(self, record: ActionRecord) -> None:
        record.action_id = len(self.records) + 1
        self.records.append(record)
        if self.stream is not None:
            self.stream.publish(
                ActionStarted(
                    record.t,
                    record.action_id,
                    record.tree,
                    record.action,
                    record.args,
                    record.carries,
                )
            )

    def ended(
        self,
        record: ActionRecord,
        outcome: Outcome,
        at_s: float,
        why: str = "",
        why_carries: Carries = NOTHING,
    ) -> None:
        """``record``'s job ended (first time only): done, failed (``why``, quoting
        ``why_carries`` of a person) or cut."""
        if record.outcome is not None:
            return
        record.outcome = outcome
        if outcome == "failed":
            record.error = why
        if self.stream is not None:
            self.stream.publish(
                ActionEnded(
                    at_s,
                    record.action_id,
                    record.tree,
                    record.action,
                    record.args,
                    record.t,
                    outcome,
                    why,
                    record.carries,
                    why_carries,
                )
            )

    @property
    def done(self) -> list[ActionRecord]:
        """The records of calls not (yet) seen failed (one cut short was begun)."""
        return [record for record in self.records if record.error is None]


class _WatchedJob:
    """A service's job seen through the log: how it ended is told once."""

    def __init__(
        self, job: Job, record: ActionRecord, log: ActionLog, actions: TreeActions
    ) -> None:
        self._job = job
        self._record = record
        self._log = log
        self._actions = actions

    def _settle(self) -> None:
        if self._record.outcome is not None or not self._job.done():
            return
        error = self._job.error()
        now = self._actions.clock.now()
        if error is not None:
            why = str(error) or type(error).__name__
            quotes: Carries = getattr(error, "carries", NOTHING)  # a safety refusal's reading
            self._log.ended(self._record, "failed", now, why, quotes)
        else:
            self._log.ended(self._record, "done", now)

    def done(self) -> bool:
        done = self._job.done()
        if done:
            self._settle()
        return done

    def error(self) -> BaseException | None:
        self._settle()
        return self._job.error()

    def result(self) -> Any:
        self._settle()
        return self._job.result()

    def cancel(self) -> None:
        if not self._job.done():  # stopped on purpose before it was done: cut, not failed
            now = self._actions.clock.now()
            self._log.ended(self._record, "cut", now, self._actions.stop_reason)
        self._job.cancel()


class Acting(Protocol):
    """The node acting now (a tree's leaf, in its tick)."""

    def carries(self) -> Carries:
        """What of a person the node's actions may be made from (what it reads)."""
        ...


@dataclass(frozen=True)
class TurnTaking:
    """How one tree takes turns with the others (see :mod:`engine.services.turns`):
    its ``priority`` (higher interrupts lower), how long an action of it waits for a
    busy resource before it is let go (``wait_for_turn_s``; 0: let go at once), and
    whether a person speaking over the robot stops its sentences (``interruptible``)."""

    turns: Turns
    priority: int = 0
    wait_for_turn_s: float = 0.0
    interruptible: bool = True


class TreeActions:
    """The services as one tree sees them: every call recorded under the tree's name.

    A service that raises while accepting work gives a failed job instead, so a node
    reports FAILURE rather than stopping the tick. The jobs returned mark their record in
    the log when they are seen failed. With ``taking`` the speaker, the face LEDs and the
    joints are shared with the other trees by priority; an action waiting for its turn
    is recorded when it starts. A free resource goes to the highest tree waiting for it. A
    tree gives way for a resource once: while that turn lasts, asking for it again (a hug
    still going on) fails at once, unsaid; its other actions go on as usual.

    Each call says what of a person its arguments were made from (``carries``: a Say
    filling in what was heard carries words); a call that does not say carries what the
    node acting reads (:attr:`acting`, set by the node's lifecycle), so a plugin's node
    that fills in a reading is never taken for the robot's own words.
    """

    def __init__(
        self,
        services: Services,
        clock: Clock,
        tree: str,
        log: ActionLog,
        *,
        taking: TurnTaking | None = None,
    ) -> None:
        self.services = services
        self.clock = clock
        self.tree = tree
        self.log = log
        self.taking = taking
        self._moved: set[str] = set()
        self._lit = False
        self.stop_reason = ""
        """Why the tree is being halted, while it is (its cut actions say so)."""
        self.round_tried_again = False
        """While the tree is halted: whether the round cut short starts again at once."""
        self.last_sentence_heard = False
        """While the tree is halted because a person spoke over it: whether the last
        sentence of what it said had begun (a question ending it was put)."""
        self.acting: Acting | None = None
        """The node whose lifecycle method runs now (its reads decide a call's carries)."""
        self._gave_way: dict[str, Turn] = {}
        """The turn each resource was last given way to: while it lasts, asking for that
        resource again fails at once, without waiting or saying so again (no stutter)."""

    def _call(
        self,
        action: str,
        args: dict[str, Any],
        start: Callable[[], Job],
        uses: tuple[str, ...] = (),
        what: str = "",
        carries: Carries | None = None,
    ) -> Job:
        made_of = carries if carries is not None else self._acting_carries()

        def begin() -> Job:
            record = ActionRecord(self.clock.now(), self.tree, action, args, carries=made_of)
            self.log.add(record)
            try:
                job = start()
            except Exception as error:  # a service refusing work is a failed action
                job = ImmediateJob(error=error)
            watched = _WatchedJob(job, record, self.log, self)
            watched.done()  # a call refused at once is marked failed at once
            return watched

        taking = self.taking
        if taking is None or not uses:
            return begin()
        turns, priority = taking.turns, taking.priority
        blocked = turns.blocking(uses, self.tree, priority)
        if blocked is None:  # free, but promised to a higher tree waiting for it?
            blocked = turns.waiting_ahead(uses, self.tree, priority)
        if blocked is not None:
            resource, turn = blocked
            if self._gave_way.get(resource) is turn:  # asked again while that turn lasts
                return ImmediateJob(error=TurnYieldedError(f"{turn.tree} still has the {resource}"))
            self._gave_way[resource] = turn  # said once; asked again once it is over
        if blocked is None:
            turns.take(uses, self.tree, priority)
            job = begin()
            if not (job.done() and job.error() is not None):  # a refused call holds nothing
                turns.hold(uses, self.tree, priority, job)
            return job
        resource, turn = blocked  # said once; the tree acts again once all are free
        if taking.wait_for_turn_s <= 0:
            return ImmediateJob(error=let_go(turns, self.tree, what, resource, turn, made_of))
        turns.tell(self.tree, "waits", resource, turn.tree)
        deadline_s = self.clock.now() + taking.wait_for_turn_s
        return WaitingJob(turns, begin, uses, self.tree, priority, deadline_s, what, made_of)

    def say(
        self,
        text: str,
        *,
        volume: float | None = None,
        carries: Carries | None = None,
        interruptible: bool | None = None,
    ) -> Job:
        """Speak ``text`` (made from ``carries`` of a person; None: what the node reads);
        ``interruptible``: whether a person's voice stops it (None: as the tree says)."""
        args: dict[str, Any] = {"text": text}
        if volume is not None:
            args["volume"] = volume
        if interruptible is None:
            interruptible = self.taking is None or self.taking.interruptible
        if not interruptible:
            args["interruptible"] = False
        return self._call(
            "say",
            args,
            lambda: self.services.speech.say(text, volume=volume, interruptible=interruptible),
            (SPEAKER,),
            f"saying {text!r}",
            carries,
        )

    def settle(self, *, lights: bool = True) -> list[Job]:
        """After the tree was halted in the middle, or gave up half-way (its round
        failed): each joint it moved since its last finished round goes back to its rest
        pose at its safe speed, and (``lights``) the face LEDs it lit go off, unless
        another tree used them since. Not subject to turns: a halted tree always comes to
        rest."""
        jobs: list[Job] = []
        for joint in sorted(self._moved):
            if self._last_user(joint_resource(joint)):
                angle_deg, speed_dps = self.services.servos.rest_pose(joint)
                args = {"joint": joint, "angle_deg": angle_deg, "rest": True}
                if speed_dps is not None:
                    args["speed_dps"] = speed_dps
                mover = self._mover(joint, angle_deg, speed_dps)
                jobs.append(self._call("servo", args, mover, carries=NOTHING))
        if lights and self._lit and self._last_user(FACE_LEDS):
            off = lambda: self.services.leds.set_color("off")  # noqa: E731
            jobs.append(self._call("led", {"color": "off", "rest": True}, off, carries=NOTHING))
        self.forget()
        return jobs

    def forget(self) -> None:
        """The tree finished a round as it meant to: what it moved and lit stays so."""
        self._moved.clear()
        self._lit = False

    def _mover(self, joint: str, angle_deg: float, speed_dps: float | None) -> Callable[[], Job]:
        return lambda: self.services.servos.move(joint, angle_deg, speed_dps=speed_dps)

    def _last_user(self, resource: str) -> bool:
        """Whether this tree used ``resource`` last (always, without turn-taking)."""
        return self.taking is None or self.taking.turns.last_user(resource) in (None, self.tree)

    def set_led(
        self, color: str, *, seconds: float | None = None, carries: Carries | None = None
    ) -> Job:
        self._lit = color != "off"
        args: dict[str, Any] = {"color": color}
        if seconds is not None:
            args["seconds"] = seconds
        return self._call(
            "led",
            args,
            lambda: self.services.leds.set_color(color, seconds=seconds),
            (FACE_LEDS,),
            f"lighting the face {color}",
            carries,
        )

    def move_servo(
        self,
        joint: str,
        angle_deg: float,
        *,
        speed_dps: float | None = None,
        carries: Carries | None = None,
    ) -> Job:
        args: dict[str, Any] = {"joint": joint, "angle_deg": angle_deg}
        if speed_dps is not None:
            args["speed_dps"] = speed_dps
        job = self._call(
            "servo",
            args,
            lambda: self.services.servos.move(joint, angle_deg, speed_dps=speed_dps),
            (joint_resource(joint),),
            f"turning {joint} to {angle_deg:g} deg",
            carries,
        )
        if getattr(job, "waiting", False) or not (job.done() and job.error() is not None):
            self._moved.add(joint)  # a move refused at once moved nothing to bring back
        return job

    def read_sensor(self, sensor: str) -> Job:
        """Ask ``sensor`` for a reading (the call names the sensor: nothing of anyone)."""
        start = lambda: self.services.sensors.read(sensor)  # noqa: E731
        return self._call("read", {"sensor": sensor}, start, carries=NOTHING)

    def report_result(
        self, command_id: str, status: str, result: Any = None, *, carries: Carries | None = None
    ) -> Job:
        """Tell the cloud how a command ended, with ``result`` (made from ``carries``)."""
        args = {"id": command_id, "status": status, "result": result}
        made_of = carries if carries is not None else self._acting_carries()
        return self._call(
            "report",
            args,
            lambda: self.services.iot.report(command_id, status, result, carries=made_of),
            carries=made_of,
        )

    def _acting_carries(self) -> Carries:
        return self.acting.carries() if self.acting is not None else NOTHING
