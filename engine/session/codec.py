"""Each session event to JSON and back: the one codec every reader that writes events uses.

An event's message is ``{"kind": kind, "t": seconds, <its fields>...}``: a recording
keeps it (format 3), ``--json`` prints it (its ``kind`` named ``event`` there), the
interop topics carry its fields. Times
(``t_s``, ``started_s``, ``from_s``, ``until_s``, clock seconds) are written as seconds
since the session's start, named without ``_s`` (``t``, ``started``, ``from``,
``until``); tuples are lists; paths are text; values follow
:mod:`engine.session.json_values` (NaN and infinities are ``null``). The fields only the
consent gate reads (:data:`~engine.session.events.GATE_ONLY`) are never written.

:func:`decode` reads a message back into its typed event, checking each field against
the event's own declaration, so a damaged or foreign message is refused by name
(:class:`EventError`), never half-built.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from engine.session.events import (
    EVENT_TYPES,
    GATE_ONLY,
    NodeInfo,
    SessionEvent,
)
from engine.session.json_values import json_value

TIMES = {"t_s": "t", "started_s": "started", "from_s": "from", "until_s": "until"}
"""The clock-time fields, and their names in a message (seconds since the start)."""
_BY_KIND: dict[str, type[SessionEvent]] = {
    event_type.kind: event_type for event_type in EVENT_TYPES
}


LATEST_S = 1e9
"""The latest time an event may have, in seconds since the session's start (31 years):
one later or before the start is damage."""


class EventError(ValueError):
    """A message that is not a session event this vest reads (the text says which field)."""


def encode(event: SessionEvent, start_s: float = 0.0) -> dict[str, Any]:
    """``event`` as its JSON message, times in seconds since ``start_s`` (clock seconds)."""
    message: dict[str, Any] = {"kind": event.kind}
    for field in dataclasses.fields(event):
        if field.name in GATE_ONLY:
            continue
        value = getattr(event, field.name)
        if field.name in TIMES:
            message[TIMES[field.name]] = round(value - start_s, 6)
        elif field.name == "nodes":
            message["nodes"] = [dataclasses.asdict(node) for node in value]
        else:
            message[field.name] = json_value(value)
    return message


def decode(message: Mapping[str, Any], start_s: float = 0.0) -> SessionEvent:
    """The event ``message`` says (times plus ``start_s``); :class:`EventError` naming the
    field when it is not one (an unknown kind, a field missing or of the wrong type)."""
    kind = message.get("kind")
    event_type = _BY_KIND.get(kind) if isinstance(kind, str) else None
    if event_type is None:
        raise EventError(f"no event of kind {kind!r}")
    values: dict[str, Any] = {}
    for field in dataclasses.fields(event_type):
        if field.name in GATE_ONLY:
            continue
        name = TIMES.get(field.name, field.name)
        if name not in message:
            if field.default is not dataclasses.MISSING:
                continue
            if field.default_factory is not dataclasses.MISSING:
                continue
            raise EventError(f"{kind}: no {name!r}")
        value = _typed(
            message[name], _hints(typing.cast(type, event_type))[field.name], f"{kind}.{name}"
        )
        if field.name in TIMES:
            if not (math.isfinite(value) and 0 <= value < LATEST_S):
                raise EventError(
                    f"{kind}.{name}: {value!r:.30} is not a time (seconds since the start, "
                    f"0 to {LATEST_S:.0e})"
                )
            value += start_s
        values[field.name] = value
    return event_type(**values)


@functools.cache
def _hints(declared: type) -> dict[str, Any]:
    """The field types ``declared`` (a dataclass) states."""
    return typing.get_type_hints(declared)


def _typed(value: Any, hint: Any, place: str) -> Any:
    """``value`` as the declared type ``hint``; EventError naming ``place`` when it is not."""
    origin = typing.get_origin(hint)
    if hint is Any or origin is dict:
        if _deeper_than(value, MAX_DEPTH):
            raise EventError(f"{place}: nested more than {MAX_DEPTH} deep")
        if hint is Any:
            return value
    if hint is float:
        if value is None:
            return math.nan  # NaN and infinities are written as null
        if isinstance(value, int | float) and not isinstance(value, bool):
            try:
                return float(value)
            except OverflowError:
                raise EventError(f"{place}: a number too large") from None
    elif hint is Path:
        if isinstance(value, str):
            return Path(value)
    elif hint is NodeInfo:
        if isinstance(value, dict):
            fields = _hints(NodeInfo)
            missing = [name for name in fields if name not in value and name != "words"]
            if missing:  # words: not told before they were kept
                raise EventError(f"{place}: no {missing[0]!r}")
            return NodeInfo(
                **{
                    name: _typed(value[name], fields[name], f"{place}.{name}")
                    for name in fields
                    if name in value
                }
            )
    elif origin is typing.Literal:
        if value in typing.get_args(hint):
            return value
    elif origin is tuple:
        item = typing.get_args(hint)[0]
        if isinstance(value, list):
            return tuple(_typed(each, item, f"{place}[]") for each in value)
    elif origin is dict:
        if isinstance(value, dict):
            return dict(value)
    elif origin in (typing.Union, types.UnionType):
        for option in typing.get_args(hint):
            try:
                return _typed(value, option, place)
            except EventError:
                continue
    elif isinstance(hint, type) and isinstance(value, hint) and not _bool_for_int(hint, value):
        return value
    raise EventError(f"{place}: {value!r:.60} is not {_named(hint)}")


MAX_DEPTH = 64
"""How deep a value of an event may nest (an action's arguments are a few levels)."""


def _deeper_than(value: Any, depth: int) -> bool:
    """Whether ``value`` nests deeper than ``depth`` lists or mappings (no recursion)."""
    level: list[Any] = [value]
    for _ in range(depth + 1):
        level = [
            item
            for each in level
            if isinstance(each, dict | list)
            for item in (each.values() if isinstance(each, dict) else each)
        ]
        if not level:
            return False
    return True


def _bool_for_int(hint: type, value: Any) -> bool:
    """JSON's true is no number, though Python's bool is an int."""
    return hint is int and isinstance(value, bool)


def _named(hint: Any) -> str:
    if typing.get_origin(hint) is typing.Literal:
        return "one of " + ", ".join(repr(option) for option in typing.get_args(hint))
    return getattr(hint, "__name__", str(hint))
