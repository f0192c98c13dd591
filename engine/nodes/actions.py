"""Actions: the robot does something. Service actions never block a tick.

Each action is RUNNING while its service works, SUCCESS when done, and FAILURE only
when it could not act (the service failed or refused); ``feedback_message`` says why.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from py_trees.common import Status

from engine.blackboard.catalogue import RANGE_CENTER_MM, RANGE_LEFT_MM, RANGE_RIGHT_MM
from engine.errors import ServiceError
from engine.nodes.base import Leaf, ServiceAction
from engine.nodes.event_reader import EQUALS, ONE_OF, EventReader, check_choice, wanted
from engine.nodes.spec import ITS_JOINT
from engine.remote_commands import LED_ARGS, MOVE_ARGS, SAY_ARGS
from engine.services.interfaces import ON_REQUEST_SENSORS
from engine.services.jobs import ImmediateJob, Job
from engine.services.turns import FACE_LEDS, SPEAKER
from engine.values.param_problems import CheckContext, ParamIssue
from engine.values.params import (
    DISTANCE_MM,
    SECONDS,
    SPEED_DPS,
    AnyValue,
    Boolean,
    Choice,
    Key,
    Number,
    Param,
    Text,
)


class Say(ServiceAction):
    """Say a phrase through the speaker.

    ``{fields}`` in the text are filled from the blackboard (``{temperature_f:.0f}``).
    RUNNING while speaking; SUCCESS when said; FAILURE when the speech service failed or
    a field has no value yet.
    """

    text, volume = SAY_ARGS  # an operator's say command takes the same (remote_commands)
    interruptible = Param(
        "interruptible",
        Boolean(),
        None,
        "whether a person speaking over the robot stops this sentence; empty: as the "
        "tree's interruptible setting says (true unless set)",
    )
    uses = (SPEAKER,)

    def start(self) -> Job:
        try:
            text = self.text.fill(self.read)
        except (KeyError, ValueError) as error:
            return ImmediateJob(error=ServiceError(str(error).strip("'\"")))
        return self.ctx.actions.say(text, volume=self.volume, interruptible=self.interruptible)


class SetLed(ServiceAction):
    """Light the face LEDs in a color, for a while or until changed.

    RUNNING for ``seconds`` (the LEDs go off afterwards); SUCCESS then (at once when no
    ``seconds``); FAILURE when the LED service failed.
    """

    color, seconds = LED_ARGS
    uses = (FACE_LEDS,)

    def start(self) -> Job:
        return self.ctx.actions.set_led(self.color, seconds=self.seconds)


class MoveServo(ServiceAction):
    """Move a joint (neck, left_arm, ...) to an angle.

    RUNNING while it moves; SUCCESS when there; FAILURE when the servo service refused
    (unknown joint, beyond the joint's limits) or failed.
    """

    joint, angle_deg, speed_dps = MOVE_ARGS
    uses = (ITS_JOINT,)

    def start(self) -> Job:
        return self.ctx.actions.move_servo(self.joint, self.angle_deg, speed_dps=self.speed_dps)


class LookToward(Leaf):
    """Turn a joint toward the nearest thing the three range sensors see (tracking).

    When the nearest reading is the left or right one, turns to +turn_deg (left) or
    -turn_deg (right); when it is the center one, or the joint already points there, or
    nothing is within max_mm, nothing moves. RUNNING while turning; SUCCESS when turned or
    when there was nothing to do; FAILURE when the servo service failed. Pre-empted while
    turning, it stops the move and turns again the next time it runs.
    """

    joint = Param("joint", Text(), "neck", "the joint to turn")
    uses = (ITS_JOINT,)
    turn_deg = Param(
        "turn_deg", Number(0.0, 90.0, "deg"), 30.0, "how far to turn; left is positive"
    )
    max_mm = Param("max_mm", DISTANCE_MM, 1200.0, "ignore anything farther")
    speed_dps = Param("speed_dps", SPEED_DPS, None, "turn speed")
    left = Param("left", Key(), RANGE_LEFT_MM, "left distance key")
    center = Param("center", Key(), RANGE_CENTER_MM, "center distance key")
    right = Param("right", Key(), RANGE_RIGHT_MM, "right distance key")

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.angle_deg = 0.0
        self.job: Job | None = None

    def nearest_side(self) -> str | None:
        """left, center or right: whichever sees the nearest thing within max_mm."""
        readings = []
        for side in ("left", "center", "right"):
            distance = self.read(getattr(self.args, side))
            if distance is not None and distance <= self.max_mm:
                readings.append((distance, side))
        return min(readings)[1] if readings else None

    def initialise(self) -> None:
        self.job = None
        side = self.nearest_side()
        target = {"left": self.turn_deg, "right": -self.turn_deg}.get(side or "center")
        if target is None or target == self.angle_deg:
            self.feedback_message = f"nearest: {side or 'nothing'}; no turn needed"
            return
        self.previous_deg = self.angle_deg
        self.angle_deg = target
        self.feedback_message = f"nearest: {side}; turning to {target:g} deg"
        self.job = self.ctx.actions.move_servo(self.joint, target, speed_dps=self.speed_dps)

    def update(self) -> Status:
        if self.job is None:
            return Status.SUCCESS
        status = self.job_status(self.job, failed="could not turn")
        if status == Status.FAILURE:
            self.angle_deg = self.previous_deg  # not there: try again next tick
        return status

    def terminate(self, new_status: Status) -> None:
        """Pre-empted mid-turn: cancel the move and forget the angle it did not reach, so
        the next round turns again."""
        turning = self.job is not None and not self.job.done()
        super().terminate(new_status)
        if new_status == Status.INVALID and turning:
            self.angle_deg = self.previous_deg


class Wait(Leaf):
    """Wait a while (engine clock).

    RUNNING until ``seconds`` have passed since it started; then SUCCESS.
    """

    seconds = Param("seconds", SECONDS, doc="how long")

    def initialise(self) -> None:
        self.until_s = self.now() + self.seconds

    def update(self) -> Status:
        return Status.SUCCESS if self.now() >= self.until_s else Status.RUNNING


class WaitForEvent(Leaf):
    """Wait for the next event on a key (a hand shown, an utterance), then go on.

    Only events that come after it starts count (those matching ``equals`` / ``one_of``
    when given). RUNNING until one comes; SUCCESS then, its value written to ``save_as``;
    FAILURE when ``seconds`` pass first (never, when not given).
    """

    key = Param("key", Key(kinds=("event",)), doc="the event key, e.g. /vision/hand/shown")
    equals = EQUALS
    one_of = ONE_OF
    save_as = Param(
        "save_as", Key(access="write"), None, "a /vars/ key to keep the event's value in"
    )
    seconds = Param("seconds", SECONDS, None, "how long to wait at most")

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        return check_choice(args, ctx)

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.events = EventReader(self, self.key, wanted(self.equals, self.one_of))
        self.until_s: float | None = None

    def initialise(self) -> None:
        self.events.skip_past()
        self.until_s = None if self.seconds is None else self.now() + self.seconds

    def update(self) -> Status:
        found, value = self.events.take()
        if found:
            if self.save_as is not None:
                self.write(self.save_as, value)
            return Status.SUCCESS
        if self.until_s is not None and self.now() >= self.until_s:
            self.feedback_message = f"no event on {self.key} within {self.seconds:g} s"
            return Status.FAILURE
        return Status.RUNNING


class SetValue(Leaf):
    """Set one of the tree's variables (``/vars/...``).

    SUCCESS always.
    """

    key = Param("key", Key(access="write"), doc="a /vars/ key")
    value = Param("value", AnyValue(), doc="the value to store")

    def update(self) -> Status:
        self.write(self.key, self.value)
        return Status.SUCCESS


class ReadSensor(ServiceAction):
    """Ask an on-request sensor (temperature, ultrasound) for a fresh reading.

    The sensor service stages the reading onto the blackboard, under the keys the robot
    config maps it to (by default /sensors/temperature/c and /f, /sensors/ultrasound/cm);
    the tree never writes it. RUNNING while the read is under way and until the reading is
    on the blackboard; SUCCESS then; FAILURE when the sensor could not be read.
    """

    sensor = Param("sensor", Choice(ON_REQUEST_SENSORS), doc="which sensor to read")

    def initialise(self) -> None:
        self.fresh: Mapping[str, Any] | None = None
        super().initialise()

    def start(self) -> Job:
        return self.ctx.actions.read_sensor(self.sensor)

    def update(self) -> Status:
        if self.fresh is None:
            return super().update()
        return self._committed()

    def finished(self, job: Job) -> Status:
        result = job.result()
        self.fresh = result if isinstance(result, Mapping) else {}
        return self._committed()

    def _committed(self) -> Status:
        """SUCCESS once every fresh value is what the blackboard holds (the commit between
        ticks has taken the staged reading in)."""
        assert self.fresh is not None
        board = self.ctx.blackboard
        waiting = [key for key, value in self.fresh.items() if board.get(key) != value]
        if waiting:
            self.feedback_message = "waiting for " + ", ".join(waiting)
            return Status.RUNNING
        self.feedback_message = ""
        return Status.SUCCESS


class ReportResult(ServiceAction):
    """Tell the cloud how a remote command ended.

    SUCCESS when the report was handed to the IoT service; FAILURE when the command has
    no id or the report could not be sent.
    """

    params: ClassVar = (
        Param("command", Key(), doc="the /vars/ key holding the command"),
        Param("status", Choice(("succeeded", "failed")), doc="how it ended"),
        Param("result", Key(), None, "a /vars/ key holding the result to send"),
    )

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        problems: list[ParamIssue] = []
        for name in ("command", "result"):
            key = args.get(name)
            if key is not None and not key.startswith("/vars/"):
                problems.append(
                    ParamIssue(name, f"{key!r} is not a tree variable", "use a /vars/ key")
                )
        return problems

    def start(self) -> Job:
        command = self.read(self.args.command)
        if not isinstance(command, Mapping) or "id" not in command:
            return ImmediateJob(error=ServiceError(f"{self.args.command} holds no command"))
        result = self.read(self.args.result) if self.args.result else None
        return self.ctx.actions.report_result(str(command["id"]), self.args.status, result)


ACTIONS = (
    Say,
    SetLed,
    MoveServo,
    LookToward,
    Wait,
    WaitForEvent,
    SetValue,
    ReadSensor,
    ReportResult,
)
