"""The one rule for writing a session's values as JSON, wherever they go: the live view,
the recording, `--json`, telemetry, the cloud's reports, MCAP, Foxglove and ROS 2.

JSON has no NaN and no infinity. A sensor that cannot be trusted reads NaN (a fault fails
safe), and every reader gets it the same way: ``null``, as a browser's ``JSON.stringify``
writes it. An event key's value is its latest event's (``null`` before the first); a
container is walked; what JSON has no type for is written as its text.
"""

from __future__ import annotations

import json
import math
from typing import Any

from engine.blackboard.events import EventLog


def json_value(value: Any) -> Any:
    """``value`` as plain JSON data (see the module's docstring): NaN and infinities are
    None, mappings have text keys, tuples are lists, anything else unknown is its text."""
    if isinstance(value, EventLog):
        return json_value(value.latest.value) if value.latest is not None else None
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(key): json_value(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [json_value(item) for item in value]
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


def json_text(value: Any, **dumps: Any) -> str:
    """``value`` written as JSON by :func:`json_value`'s rule (``dumps``: json.dumps's
    layout options, such as ``ensure_ascii`` or ``separators``)."""
    return json.dumps(json_value(value), allow_nan=False, **dumps)
