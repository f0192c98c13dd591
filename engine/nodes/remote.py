"""CarryOut: do what a remote operator asked (the iot_command behavior).

A command is ``{"id": ..., "type": ..., "args": {...}}``. Types:

- ``say``: ``{text, volume?}``
- ``led``: ``{color, seconds?}``
- ``move``: ``{joint, angle_deg, speed_dps?}``
- ``read``: ``{sensor}``: temperature or ultrasound (read on request), or touch, force,
  range, gesture (the latest values on the blackboard)
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from py_trees.common import Status

from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    GESTURE_LAST,
    IOT_CANCELED,
    RANGE_CENTER_MM,
    RANGE_LEFT_MM,
    RANGE_RIGHT_MM,
    TOUCH_ANY,
    TOUCH_PADS,
    default_catalogue,
)
from engine.blackboard.events import EventLog
from engine.errors import ServiceError
from engine.nodes.actions import MoveServo, Say, SetLed
from engine.nodes.base import Leaf, ServiceAction, declared_params
from engine.nodes.event_reader import EventReader
from engine.services.jobs import ImmediateJob, Job
from engine.values.params import SECONDS, CheckContext, Key, Param, ParamProblem, did_you_mean
from engine.values.templates import Template

POLLED_READINGS: dict[str, tuple[str, ...]] = {
    "touch": (TOUCH_PADS, TOUCH_ANY),
    "force": (FORCE_LEFT_N, FORCE_RIGHT_N),
    "range": (RANGE_LEFT_MM, RANGE_CENTER_MM, RANGE_RIGHT_MM),
    "gesture": (GESTURE_LAST,),
}
COMMAND_TYPES = ("say", "led", "move", "read")


class CommandError(ServiceError):
    """A remote command is malformed; the message says what to send instead."""


ACTION_NODES: dict[str, type[Leaf]] = {"say": Say, "led": SetLed, "move": MoveServo}
"""The node whose declaration checks each acting command's arguments: one set of rules
for a tree's parameters and an operator's arguments."""


def checked_args(command_type: str, args: Mapping[str, Any], ctx: CheckContext) -> dict[str, Any]:
    """``args`` converted by the parameters ``ACTION_NODES[command_type]`` declares.

    Raises CommandError naming the argument, the value and what is expected: unknown
    names, missing required ones, wrong types, NaN, inf, numbers past their bounds, text
    past its length. Text is taken as written (an operator's braces are no template).
    """
    declared = {param.name: param for param in declared_params(ACTION_NODES[command_type])}
    for name in args:
        if name not in declared:
            hint = did_you_mean(str(name), list(declared)) or "arguments: " + ", ".join(declared)
            raise CommandError(f"unknown argument {name!r} for {command_type} ({hint})")
    values: dict[str, Any] = {}
    for name, param in declared.items():
        raw = args.get(name)
        if raw is None:
            if param.required:
                raise CommandError(f"{command_type} needs {name!r}: {param.doc}")
            values[name] = param.default
            continue
        if isinstance(param.type, Template) and isinstance(raw, str):
            raw = raw.replace("{", "{{").replace("}", "}}")
        try:
            values[name] = param.type.convert(raw, ctx)
        except ParamProblem as problem:
            hint = f" ({problem.hint})" if problem.hint else ""
            raise CommandError(f"{name!r} {problem.message}{hint}") from None
    return values


class CarryOut(ServiceAction):
    """Carry out a remote command (say, led, move, read).

    RUNNING while the service works; SUCCESS when done, with the result saved to
    ``save_result_as``; FAILURE when the command is malformed, the service failed, the
    command took longer than ``timeout_s`` or the operator canceled it meanwhile (its
    action is cut short), with ``{"error": why}`` saved there instead.
    Arguments are checked by the declarations of Say, SetLed and MoveServo. The result
    saved always belongs to this command (it is cleared when the command starts).
    """

    command = Param("command", Key(), doc="the /vars/ key holding the command")
    save_result_as = Param(
        "save_result_as", Key(access="write"), None, "a /vars/ key for the result"
    )
    timeout_s = Param("timeout_s", SECONDS, 60.0, "FAILURE when a command takes longer, in seconds")
    reads: ClassVar = (*(key for keys in POLLED_READINGS.values() for key in keys), IOT_CANCELED)

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.cancels = EventReader(self, IOT_CANCELED, None)

    def initialise(self) -> None:
        if self.save_result_as:
            self.write(self.save_result_as, None)
        self.started_s = self.now()
        self.cancels.skip_past()  # only a cancel of this command, from now on, counts
        super().initialise()

    def _canceled(self) -> bool:
        """Whether the operator canceled this command (an ``/iot/canceled`` event)."""
        command = self.read(self.command)
        wanted = command.get("id") if isinstance(command, Mapping) else None
        while True:
            found, command_id = self.cancels.take()
            if not found:
                return False
            if command_id == wanted:
                return True

    def start(self) -> Job:
        command = self.read(self.command)
        try:
            if not isinstance(command, Mapping):
                raise CommandError(f"{self.command} holds no command")
            kind = command.get("type")
            args = command.get("args") or {}
            if not isinstance(args, Mapping):
                raise CommandError(f"'args' must be a mapping, got {_shown(args)}")
            handler = self._handlers().get(kind) if isinstance(kind, str) else None
            if handler is None:
                raise CommandError(
                    f"unknown command type {_shown(kind)} (known: {', '.join(COMMAND_TYPES)})"
                )
            return handler(args)
        except CommandError as error:
            return ImmediateJob(error=error)

    def _handlers(self) -> dict[str, Callable[[Mapping[str, Any]], Job]]:
        return {"say": self._say, "led": self._led, "move": self._move, "read": self._read}

    def _check(self, kind: str, args: Mapping[str, Any]) -> dict[str, Any]:
        return checked_args(kind, args, CheckContext(self.ctx.blackboard.catalogue))

    def _say(self, args: Mapping[str, Any]) -> Job:
        values = self._check("say", args)
        return self.ctx.actions.say(values["text"].fill(self.read), volume=values["volume"])

    def _led(self, args: Mapping[str, Any]) -> Job:
        values = self._check("led", args)
        return self.ctx.actions.set_led(values["color"], seconds=values["seconds"])

    def _move(self, args: Mapping[str, Any]) -> Job:
        values = self._check("move", args)
        return self.ctx.actions.move_servo(
            values["joint"], values["angle_deg"], speed_dps=values["speed_dps"]
        )

    def _read(self, args: Mapping[str, Any]) -> Job:
        sensor = args.get("sensor")
        if not isinstance(sensor, str) or not sensor:
            raise CommandError(f"'sensor' must be non-empty text, got {_shown(sensor)}")
        if set(args) - {"sensor"}:
            raise CommandError(f"read takes only 'sensor', got {', '.join(map(str, args))}")
        if sensor in ("temperature", "ultrasound"):
            return self.ctx.actions.read_sensor(sensor)
        keys = POLLED_READINGS.get(sensor)
        if keys is None:
            known = ", ".join(READABLE_SENSORS)
            raise CommandError(f"unknown sensor {_shown(sensor)} (known: {known})")
        values = {key: self.read(key) for key in keys}
        for key, value in values.items():
            if isinstance(value, EventLog):
                values[key] = value.latest.value if value.latest else None
        return ImmediateJob(values)

    def _cut(self, why: str) -> Status:
        """Stop the command's action short (told as cut, ``why``): FAILURE."""
        self.ctx.actions.stop_reason = why
        try:
            if self.job is not None:
                self.job.cancel()
        finally:
            self.ctx.actions.stop_reason = ""
        self.feedback_message = why
        return Status.FAILURE

    def finished(self, job: Job) -> Status:
        result = job.result()  # a reading is staged by the sensor service, not written here
        if self.save_result_as:
            self.write(self.save_result_as, result)
        return Status.SUCCESS

    def update(self) -> Status:
        status = super().update()
        if status == Status.RUNNING and self._canceled():
            status = self._cut("canceled by the operator")
        if status == Status.RUNNING and self.now() - self.started_s > self.timeout_s:
            status = self._cut(f"timed out after {self.timeout_s:g} s")
        if status == Status.FAILURE and self.save_result_as:
            self.write(self.save_result_as, {"error": self.feedback_message})
        return status


READABLE_SENSORS = ("temperature", "ultrasound", *POLLED_READINGS)


def command_problem(kind: str, args: Mapping[str, Any]) -> str | None:
    """What is wrong with a command's arguments, checked as the robot will check them
    (the service answers 422 at once instead of the robot FAILED later); None when they
    are fine, or when ``kind`` is not built in (the robot decides). What only the robot
    knows (its joints and their limits) is checked there."""
    try:
        if kind in ACTION_NODES:
            checked_args(kind, args, CheckContext(default_catalogue()))
        elif kind == "read":
            sensor = args.get("sensor")
            if sensor not in READABLE_SENSORS or set(args) - {"sensor"}:
                return f"read takes 'sensor', one of {', '.join(READABLE_SENSORS)}"
    except CommandError as error:
        return str(error)
    return None


def command_catalogue() -> dict[str, list[dict[str, Any]]]:
    """Each command type's arguments as an operator's page builds its form from them:
    ``{type: [{"name", "doc", "required", "schema"}]}`` (schema: JSON Schema of a value).
    The same declarations check the arguments when the robot carries a command out."""
    catalogue = {
        kind: [
            {
                "name": param.name,
                "doc": param.doc,
                "required": param.required,
                "schema": param.type.json_schema(),
            }
            for param in declared_params(node)
        ]
        for kind, node in ACTION_NODES.items()
    }
    catalogue["read"] = [
        {
            "name": "sensor",
            "doc": "which sensor to read",
            "required": True,
            "schema": {"enum": list(READABLE_SENSORS)},
        }
    ]
    return catalogue


def _shown(value: Any) -> str:
    """A value as an operator reads it in an error: short, and never a wall of text."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


REMOTE_NODES = (CarryOut,)
