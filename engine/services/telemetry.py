"""What the robot tells the cloud as telemetry: the latest committed sensor and device
values, made safe for JSON.

:class:`TelemetrySnapshot` is a session reader: the telemetry thread of
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
    """A session reader: the latest committed value of each sensor and device key, kept
    for the telemetry thread, which takes a copy (:meth:`take`)."""

    def __init__(self) -> None:
        self._values: dict[str, Any] = {}
        self._lock = threading.Lock()
        self.prefixes: tuple[str, ...] = TELEMETRY_PREFIXES
        """The keys sent: sensors and devices, or devices alone when the person did not
        consent to telemetry (:meth:`devices_only`)."""

    @property
    def sensors_allowed(self) -> bool:
        return SENSORS_PREFIX in self.prefixes

    def devices_only(self) -> None:
        """From now on only the robot's own device keys are sent, never a sensor reading."""
        with self._lock:
            self.prefixes = (DEVICES_PREFIX,)
            self._values = {k: v for k, v in self._values.items() if k.startswith(DEVICES_PREFIX)}

    def on_event(self, event: SessionEvent) -> None:
        if isinstance(event, KeyChanged) and event.key.startswith(self.prefixes):
            value = json_safe(event.value)
            with self._lock:
                self._values[event.key] = value

    def take(self) -> dict[str, Any]:
        with self._lock:
            return dict(self._values)


WITHHELD = "not sent: the person's consent does not cover sensor readings sent off the robot"
"""A command's result that carries sensor values, when the person did not consent."""


def carries_sensor_values(value: Any) -> bool:
    """Whether ``value`` (a command's result) holds a sensor or camera key's value."""
    if isinstance(value, dict):
        return any(
            str(key).startswith((SENSORS_PREFIX, "/vision/")) or carries_sensor_values(item)
            for key, item in value.items()
        )
    if isinstance(value, list | tuple):
        return any(carries_sensor_values(item) for item in value)
    return False
