"""What the robot tells the cloud as telemetry: the latest committed sensor and device
values, made safe for JSON.

:class:`TelemetrySnapshot` reads the consent gate's ``sent`` exit (only what may leave
the robot reaches it): the telemetry thread of
:class:`~engine.services.cloud_link.CloudLink` takes a copy of what the scheduler last
committed, never the live blackboard.
"""

from __future__ import annotations

import threading
from typing import Any

from engine.blackboard.catalogue import DEVICES_PREFIX, SENSORS_PREFIX
from engine.session.events import KeyChanged, SessionEvent
from engine.session.json_values import json_value

TELEMETRY_PREFIXES = (SENSORS_PREFIX, DEVICES_PREFIX)


class TelemetrySnapshot:
    """A reader of what may leave the robot: the latest committed value of each sensor
    and device key, kept for the telemetry thread, which takes a copy (:meth:`take`)."""

    def __init__(self) -> None:
        self._values: dict[str, Any] = {}
        self._lock = threading.Lock()

    def on_event(self, event: SessionEvent) -> None:
        if isinstance(event, KeyChanged) and event.key.startswith(TELEMETRY_PREFIXES):
            value = json_value(event.value)
            with self._lock:
                self._values[event.key] = value

    def take(self) -> dict[str, Any]:
        with self._lock:
            return dict(self._values)
