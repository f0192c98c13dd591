"""What an operator may ask a robot: the command types, their arguments and their checks.

Shared by the robot (the CarryOut node carries a command out) and the cloud service (it
answers 422 at once for arguments the robot would refuse, and builds the operator's form
from :func:`command_catalogue`). The arguments of ``say``, ``led`` and ``move`` are the
parameters of the Say, SetLed and MoveServo nodes: declared here once, so a tree and an
operator are held to the same rules. Imports no py_trees: the cloud loads no robot code.

- ``say``: ``{text, volume?}``
- ``led``: ``{color, seconds?}``
- ``move``: ``{joint, angle_deg, speed_dps?}``
- ``read``: ``{sensor}``: temperature or ultrasound (read on request), or touch, force,
  range, gesture (the latest values on the blackboard)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    GESTURE_LAST,
    RANGE_CENTER_MM,
    RANGE_LEFT_MM,
    RANGE_RIGHT_MM,
    TOUCH_ANY,
    TOUCH_PADS,
    default_catalogue,
)
from engine.colors import NAMED_COLORS, parse_color
from engine.errors import ServiceError
from engine.values.param_problems import CheckContext, ParamProblem, did_you_mean
from engine.values.params import SECONDS, SPEED_DPS, Number, Param, ParamType, Text
from engine.values.templates import Template

MAX_SAID_CHARS = 1000
"""The longest phrase one Say speaks (about a minute of speech)."""


class Color(ParamType[str]):
    """A color name (pink, blue, ...) or #RRGGBB."""

    name = "color"

    def json_schema(self) -> dict[str, Any]:
        return {"anyOf": [{"enum": list(NAMED_COLORS)}, {"type": "string", "pattern": "^#"}]}

    def convert(self, value: Any, ctx: CheckContext) -> str:
        try:
            parse_color(str(value))
        except ValueError:
            nearest = did_you_mean(str(value), list(NAMED_COLORS))
            known = "colors: " + ", ".join(NAMED_COLORS) + ", or #RRGGBB"
            raise ParamProblem(
                f"unknown color {value!r}", f"{nearest} {known}" if nearest else known
            ) from None
        return str(value)


SAY_ARGS: tuple[Param[Any], ...] = (
    Param(
        "text",
        Template(max_chars=MAX_SAID_CHARS),
        doc="what to say; {key} fields are filled from the blackboard",
    ),
    Param("volume", Number(0.0, 1.0), None, "0..1; empty: the robot's default volume"),
)
LED_ARGS: tuple[Param[Any], ...] = (
    Param("color", Color(), doc="a color name (pink, blue, off, ...) or #RRGGBB"),
    Param("seconds", SECONDS, None, "how long to keep it lit; empty: until the next color"),
)
MOVE_ARGS: tuple[Param[Any], ...] = (
    Param("joint", Text(), doc="joint name from the robot config, e.g. neck"),
    Param("angle_deg", Number(-180.0, 180.0, "deg"), doc="target angle in degrees"),
    Param("speed_dps", SPEED_DPS, None, "degrees per second; empty: the joint's own maximum"),
)
ACTION_ARGS: dict[str, tuple[Param[Any], ...]] = {
    "say": SAY_ARGS,
    "led": LED_ARGS,
    "move": MOVE_ARGS,
}
"""Each acting command's arguments: the parameters of the node that acts the same way."""

POLLED_READINGS: dict[str, tuple[str, ...]] = {
    "touch": (TOUCH_PADS, TOUCH_ANY),
    "force": (FORCE_LEFT_N, FORCE_RIGHT_N),
    "range": (RANGE_LEFT_MM, RANGE_CENTER_MM, RANGE_RIGHT_MM),
    "gesture": (GESTURE_LAST,),
}
COMMAND_TYPES = ("say", "led", "move", "read")


class CommandError(ServiceError):
    """A remote command is malformed; the message says what to send instead."""


def checked_args(command_type: str, args: Mapping[str, Any], ctx: CheckContext) -> dict[str, Any]:
    """``args`` converted by the arguments ``ACTION_ARGS[command_type]`` declares.

    Raises CommandError naming the argument, the value and what is expected: unknown
    names, missing required ones, wrong types, NaN, inf, numbers past their bounds, text
    past its length. Text is taken as written (an operator's braces are no template).
    """
    declared = {param.name: param for param in ACTION_ARGS[command_type]}
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


READABLE_SENSORS = ("temperature", "ultrasound", *POLLED_READINGS)


def command_problem(kind: str, args: Mapping[str, Any]) -> str | None:
    """What is wrong with a command's arguments, checked as the robot will check them
    (the service answers 422 at once instead of the robot FAILED later); None when they
    are fine, or when ``kind`` is not built in (the robot decides). What only the robot
    knows (its joints and their limits) is checked there."""
    try:
        if kind in ACTION_ARGS:
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
            for param in params
        ]
        for kind, params in ACTION_ARGS.items()
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
