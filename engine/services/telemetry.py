"""What the robot tells the cloud as telemetry: the latest committed sensor and device
values, made safe for JSON.

:class:`TelemetrySnapshot` reads the consent gate's ``sent`` exit (only what may leave
the robot reaches it): the telemetry thread of
:class:`~engine.services.cloud_link.CloudLink` takes a copy of what the scheduler last
committed, never the live blackboard.
"""

from __future__ import annotations

import math
import threading
from typing import Any

from engine.blackboard.catalogue import DEVICES_PREFIX, SENSORS_PREFIX
from engine.blackboard.events import EventLog
from engine.session.events import KeyChanged, SessionEvent

TELEMETRY_PREFIXES = (SENSORS_PREFIX, DEVICES_PREFIX)


def json_safe(value: Any) -> Any:
    """Numbers that JSON cannot carry (NaN, infinity) as None; containers walked; an
    event key as its latest event's value (None before the first)."""
    if isinstance(value, EventLog):
        return json_safe(value.latest.value) if value.latest is not None else None
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


class TelemetrySnapshot:
    """A reader of what may leave the robot: the latest committed value of each sensor
    and device key, kept for the telemetry thread, which takes a copy (:meth:`take`)."""

    def __init__(self) -> None:
        self._values: dict[str, Any] = {}
        self._lock = threading.Lock()

    def on_event(self, event: SessionEvent) -> None:
        if isinstance(event, KeyChanged) and event.key.startswith(TELEMETRY_PREFIXES):
            value = json_safe(event.value)
            with self._lock:
                self._values[event.key] = value

    def take(self) -> dict[str, Any]:
        with self._lock:
            return dict(self._values)
