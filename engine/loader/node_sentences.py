"""What a leaf does, in words a person reads: "force on the left side pad above 5 N?",
not "Check, key: /sensors/force/left_n, above: 5".

One place says it for the editor's outline, the drawings (``vest render``) and the live
view, from a node's type and its parameters as written (a ``${setting}`` is said as its
name). A question ends with "?"; an action is said as what the robot does. A node type
this module does not know (a plugin's) is said as its type and parameters.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import Any

from engine.blackboard.catalogue import VARIABLES_PREFIX, KeyCatalogue

Args = Mapping[str, Any]


def node_sentence(type_name: str, args: Args, catalogue: KeyCatalogue) -> str | None:
    """The sentence of a leaf of ``type_name`` with ``args`` (None: no sentence for it)."""
    said = _SENTENCES.get(type_name)
    return None if said is None else said(args, _Keys(catalogue))


class _Keys:
    """A blackboard key in words: its description and unit from the catalogue."""

    def __init__(self, catalogue: KeyCatalogue) -> None:
        self.catalogue = catalogue

    def words(self, key: Any) -> str:
        if str(key).startswith(VARIABLES_PREFIX):
            return f"the variable {str(key).removeprefix(VARIABLES_PREFIX)}"
        spec = self.catalogue.lookup(str(key))
        if spec is None or not spec.description:
            return str(key)
        return spec.description.split(":")[0].split(" (")[0]  # its name, not its details

    def unit(self, key: Any) -> str:
        spec = self.catalogue.lookup(str(key))
        return f" {spec.unit}" if spec is not None and spec.unit else ""


def _value(value: Any) -> str:
    """A parameter's value as a sentence says it (a ``${setting}`` by its name)."""
    value = getattr(value, "source", value)  # a text template, as written
    if isinstance(value, str) and value.startswith("${") and value.endswith("}"):
        return value[2:-1]
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list):
        return ", ".join(_value(item) for item in value)
    return str(value)


def _check(args: Args, keys: _Keys) -> str:
    args = {name: value for name, value in args.items() if value is not None}  # not given
    key = args.get("key", "?")
    what = keys.words(key)
    if args.get("item") is not None:
        what = f"item {args['item']} of {what}"
    unit = keys.unit(key)
    if "above" in args:
        return f"{what} above {_value(args['above'])}{unit}?"
    if "below" in args:
        return f"{what} below {_value(args['below'])}{unit}?"
    if "between" in args and isinstance(args["between"], list) and len(args["between"]) == 2:
        low, high = args["between"]
        return f"{what} between {_value(low)} and {_value(high)}{unit}?"
    state = re.sub(r"^(true|yes) (while|when|if) ", "", what, flags=re.IGNORECASE)
    if args.get("equals") is True:
        return f"{state}?" if state != what else f"{what}: yes?"
    if args.get("equals") is False:
        return f"not: {state}?" if state != what else f"{what}: no?"
    if "equals" in args:
        return f"{what} is {_value(args['equals'])}{unit}?"
    if "not_equals" in args:
        return f"{what} is not {_value(args['not_equals'])}{unit}?"
    return f"{what}?"


def _event(args: Args, keys: _Keys) -> str:
    which = ""
    if args.get("equals") is not None:
        which = f": {_value(args['equals'])}"
    elif args.get("one_of"):
        which = f": one of {_value(args['one_of'])}"
    return f"new: {keys.words(args.get('key', '?'))}{which}?"


def _pat(args: Args, keys: _Keys) -> str:
    on = f" on {_value(args['pads'])}" if args.get("pads") else ""
    but = f", not on {_value(args['except_pads'])}" if args.get("except_pads") else ""
    return f"a pat{on}{but}?"


def _led(args: Args, keys: _Keys) -> str:
    if args.get("color") == "off":
        return "turn the face lights off"
    seconds = f" for {_value(args['seconds'])} s" if args.get("seconds") is not None else ""
    return f"light the face {_value(args.get('color', '?'))}{seconds}"


def _move(args: Args, keys: _Keys) -> str:
    speed = f" at {_value(args['speed_dps'])} deg/s" if args.get("speed_dps") is not None else ""
    return (
        f"turn {_value(args.get('joint', '?'))} to {_value(args.get('angle_deg', '?'))} deg{speed}"
    )


def _wait_for(args: Args, keys: _Keys) -> str:
    within = f" (at most {_value(args['seconds'])} s)" if args.get("seconds") is not None else ""
    return f"wait for {_event(args, keys).removesuffix('?')}{within}"


_SENTENCES: dict[str, Callable[[Args, _Keys], str]] = {
    "Check": _check,
    "Fresh": lambda a, k: (
        f"{k.words(a.get('key', '?'))}, read in the last {_value(a.get('within_s', '?'))} s?"
    ),
    "OnEvent": _event,
    "OnTouch": _pat,
    "Say": lambda a, k: f"say \u201c{_value(a.get('text', ''))}\u201d",
    "SetLed": _led,
    "MoveServo": _move,
    "LookToward": lambda a, k: f"turn {_value(a.get('joint', 'neck'))} toward the nearest person",
    "Wait": lambda a, k: f"wait {_value(a.get('seconds', '?'))} s",
    "WaitForEvent": _wait_for,
    "ReadSensor": lambda a, k: f"read the {_value(a.get('sensor', '?'))} sensor",
    "SetValue": lambda a, k: f"remember {_value(a.get('value'))} as {a.get('key', '?')}",
    "Reply": lambda a, k: "answer what was heard, by the dialog's rules",
    "CarryOut": lambda a, k: "carry out the operator's command",
    "ReportResult": lambda a, k: "tell the operator how the command went",
}
