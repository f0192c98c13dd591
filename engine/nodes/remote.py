"""CarryOut: do what a remote operator asked (the iot_command behavior).

A command is ``{"id": ..., "type": ..., "args": {...}}``; its types and arguments, and
their checks, are in :mod:`engine.remote_commands` (shared with the cloud service).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from py_trees.common import Status

from engine.blackboard.catalogue import IOT_CANCELED, NOTHING, READINGS, Carries
from engine.blackboard.events import EventLog
from engine.nodes.base import ServiceAction
from engine.nodes.event_reader import EventReader
from engine.nodes.spec import ANY_JOINT
from engine.remote_commands import (
    COMMAND_TYPES,
    POLLED_READINGS,
    READABLE_SENSORS,
    CommandError,
    checked_args,
)
from engine.services.jobs import ImmediateJob, Job
from engine.services.turns import FACE_LEDS, SPEAKER
from engine.values.param_problems import CheckContext
from engine.values.params import SECONDS, Key, Param
from engine.values.templates import CompiledTemplate


class CarryOut(ServiceAction):
    """Carry out a remote command (say, led, move, read).

    RUNNING while the service works; SUCCESS when done, with the result saved to
    ``save_result_as``; FAILURE when the command is malformed, the service failed, the
    command took longer than ``timeout_s`` or the operator canceled it meanwhile (its
    action is cut short), with ``{"error": why}`` saved there instead.
    Arguments are checked as Say, SetLed and MoveServo check their parameters. The result
    saved always belongs to this command (it is cleared when the command starts).
    """

    uses = (SPEAKER, FACE_LEDS, ANY_JOINT)  # a remote command may speak, light or move

    command = Param("command", Key(), doc="the /vars/ key holding the command")
    save_result_as = Param(
        "save_result_as", Key(access="write"), None, "a /vars/ key for the result"
    )
    timeout_s = Param("timeout_s", SECONDS, 60.0, "FAILURE when a command takes longer, in seconds")
    reads: ClassVar = (*(key for keys in POLLED_READINGS.values() for key in keys), IOT_CANCELED)

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.cancels = EventReader(self, IOT_CANCELED, None)
        self.made_of: Carries = NOTHING
        """What of a person the command's action and result are made from: a read's
        result is readings; a say's text what its fields fill in; the rest nothing."""

    def initialise(self) -> None:
        if self.save_result_as:
            self.write(self.save_result_as, None, carries=NOTHING)
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
        self.made_of = NOTHING
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
        text: CompiledTemplate = values["text"]
        self.made_of = self.ctx.blackboard.carried_by(text.keys)
        said = text.fill(self.read)
        return self.ctx.actions.say(said, volume=values["volume"], carries=self.made_of)

    def _led(self, args: Mapping[str, Any]) -> Job:
        values = self._check("led", args)
        return self.ctx.actions.set_led(values["color"], seconds=values["seconds"], carries=NOTHING)

    def _move(self, args: Mapping[str, Any]) -> Job:
        values = self._check("move", args)
        return self.ctx.actions.move_servo(
            values["joint"], values["angle_deg"], speed_dps=values["speed_dps"], carries=NOTHING
        )

    def _read(self, args: Mapping[str, Any]) -> Job:
        sensor = args.get("sensor")
        if not isinstance(sensor, str) or not sensor:
            raise CommandError(f"'sensor' must be non-empty text, got {_shown(sensor)}")
        if set(args) - {"sensor"}:
            raise CommandError(f"read takes only 'sensor', got {', '.join(map(str, args))}")
        self.made_of = frozenset({READINGS})
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

    def terminate(self, new_status: Status) -> None:
        """Halted under way (spoken over, interrupted, paused, stopped): the action is cut
        short and the operator told at once that the command failed, with why, unless the
        round starts again and carries the command out anew."""
        under_way = new_status == Status.INVALID and self.status == Status.RUNNING
        super().terminate(new_status)
        if not under_way or self.ctx.actions.round_tried_again:
            return
        command = self.read(self.command)
        if isinstance(command, Mapping) and "id" in command:
            why = f"cut short: {self.ctx.actions.stop_reason or 'its tree was halted'}"
            self.ctx.actions.report_result(
                str(command["id"]), "failed", {"error": why}, carries=self.made_of
            )

    def finished(self, job: Job) -> Status:
        result = job.result()  # a reading is staged by the sensor service, not written here
        if self.save_result_as:
            self.write(self.save_result_as, result, carries=self.made_of)
        return Status.SUCCESS

    def update(self) -> Status:
        status = super().update()
        if status == Status.RUNNING and self._canceled():
            status = self._cut("canceled by the operator")
        if status == Status.RUNNING and self.now() - self.started_s > self.timeout_s:
            status = self._cut(f"timed out after {self.timeout_s:g} s")
        if status == Status.FAILURE and self.save_result_as:
            error = {"error": self.feedback_message}  # which may quote the command's text
            self.write(self.save_result_as, error, carries=self.made_of)
        return status


def _shown(value: Any) -> str:
    """A value as an operator reads it in an error: short, and never a wall of text."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


REMOTE_NODES = (CarryOut,)
