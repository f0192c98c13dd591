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

from engine.blackboard.events import EventLog
from engine.colors import parse_color
from engine.errors import ServiceError
from engine.nodes.base import ServiceAction
from engine.services.jobs import ImmediateJob, Job
from engine.values.params import Key, Param

POLLED_READINGS: dict[str, tuple[str, ...]] = {
    "touch": ("/sensors/touch/pads", "/sensors/touch/any"),
    "force": ("/sensors/force/left_n", "/sensors/force/right_n"),
    "range": ("/sensors/range/left_mm", "/sensors/range/center_mm", "/sensors/range/right_mm"),
    "gesture": ("/sensors/gesture/last",),
}
ON_REQUEST_KEYS = frozenset(
    {"/sensors/temperature/c", "/sensors/temperature/f", "/sensors/ultrasound/cm"}
)
COMMAND_TYPES = ("say", "led", "move", "read")


class CommandError(ServiceError):
    """A remote command is malformed; the message says what to send instead."""


def _number(args: Mapping[str, Any], name: str, *, required: bool = True) -> float | None:
    value = args.get(name)
    if value is None and not required:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise CommandError(f"'{name}' must be a number, got {value!r}")
    return float(value)


def _text(args: Mapping[str, Any], name: str) -> str:
    value = args.get(name)
    if not isinstance(value, str) or not value:
        raise CommandError(f"'{name}' must be non-empty text, got {value!r}")
    return value


class CarryOut(ServiceAction):
    """Carry out a remote command (say, led, move, read).

    RUNNING while the service works; SUCCESS when done, with the result saved to
    ``save_result_as``; FAILURE when the command is malformed or the service failed, with
    ``{"error": why}`` saved there instead.
    """

    params: ClassVar = (
        Param("command", Key(), doc="the /vars/ key holding the command"),
        Param("save_result_as", Key(access="write"), None, "a /vars/ key for the result"),
    )
    reads: ClassVar = tuple(key for keys in POLLED_READINGS.values() for key in keys)
    writes: ClassVar = tuple(sorted(ON_REQUEST_KEYS))

    def start(self) -> Job:
        command = self.read(self.args.command)
        try:
            if not isinstance(command, Mapping):
                raise CommandError(f"{self.args.command} holds no command")
            kind = command.get("type")
            args = command.get("args") or {}
            if not isinstance(args, Mapping):
                raise CommandError(f"'args' must be a mapping, got {args!r}")
            handler = self._handlers().get(str(kind))
            if handler is None:
                raise CommandError(
                    f"unknown command type {kind!r} (known: {', '.join(COMMAND_TYPES)})"
                )
            return handler(args)
        except CommandError as error:
            return ImmediateJob(error=error)

    def _handlers(self) -> dict[str, Callable[[Mapping[str, Any]], Job]]:
        return {"say": self._say, "led": self._led, "move": self._move, "read": self._read}

    def _say(self, args: Mapping[str, Any]) -> Job:
        volume = _number(args, "volume", required=False)
        return self.ctx.actions.say(_text(args, "text"), volume=volume)

    def _led(self, args: Mapping[str, Any]) -> Job:
        color = _text(args, "color")
        try:
            parse_color(color)
        except ValueError as error:
            raise CommandError(str(error)) from None
        return self.ctx.actions.set_led(color, seconds=_number(args, "seconds", required=False))

    def _move(self, args: Mapping[str, Any]) -> Job:
        angle = _number(args, "angle_deg")
        assert angle is not None
        return self.ctx.actions.move_servo(
            _text(args, "joint"), angle, speed_dps=_number(args, "speed_dps", required=False)
        )

    def _read(self, args: Mapping[str, Any]) -> Job:
        sensor = _text(args, "sensor")
        if sensor in ("temperature", "ultrasound"):
            return self.ctx.actions.read_sensor(sensor)
        keys = POLLED_READINGS.get(sensor)
        if keys is None:
            known = ", ".join(("temperature", "ultrasound", *POLLED_READINGS))
            raise CommandError(f"unknown sensor {sensor!r} (known: {known})")
        values = {key: self.read(key) for key in keys}
        for key, value in values.items():
            if isinstance(value, EventLog):
                values[key] = value.latest.value if value.latest else None
        return ImmediateJob(values)

    def finished(self, job: Job) -> Status:
        result = job.result()
        if isinstance(result, Mapping):
            for key, value in result.items():
                if key in ON_REQUEST_KEYS:
                    self.ctx.blackboard.set(key, value)
        if self.args.save_result_as:
            self.write(self.args.save_result_as, result)
        return Status.SUCCESS

    def update(self) -> Status:
        status = super().update()
        if status == Status.FAILURE and self.args.save_result_as:
            self.write(self.args.save_result_as, {"error": self.feedback_message})
        return status


REMOTE_NODES = (CarryOut,)
