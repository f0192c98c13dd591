"""What trees ask of services, recorded: the robot's timeline.

:class:`TreeActions` is the one door from a tree's nodes to the services. Each call
becomes an :class:`ActionRecord` (time, tree, action, args) handed to every listener of
the :class:`ActionLog`: the timeline printer, the ``--json`` writer, the test harness.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from engine.clock import Clock
from engine.services.interfaces import Services
from engine.services.jobs import ImmediateJob, Job

_log = logging.getLogger("vest.actions")


@dataclass(frozen=True)
class ActionRecord:
    """One service call: ``t`` in clock seconds, the tree, the action name and its arguments."""

    t: float
    tree: str
    action: str
    args: dict[str, Any]

    def to_json(self) -> dict[str, Any]:
        return {"t": round(self.t, 3), "tree": self.tree, "action": self.action, "args": self.args}


@dataclass
class ActionLog:
    """Keeps every record and tells listeners as they come."""

    records: list[ActionRecord] = field(default_factory=list)
    listeners: list[Callable[[ActionRecord], None]] = field(default_factory=list)

    def add(self, record: ActionRecord) -> None:
        self.records.append(record)
        for listener in self.listeners:
            try:
                listener(record)
            except Exception:  # a broken display must not stop the robot acting
                _log.exception("action listener %r failed", listener)


class TreeActions:
    """The services as one tree sees them: every call recorded under the tree's name.

    A service that raises while accepting work gives a failed job instead, so a node
    reports FAILURE rather than stopping the tick.
    """

    def __init__(self, services: Services, clock: Clock, tree: str, log: ActionLog) -> None:
        self.services = services
        self.clock = clock
        self.tree = tree
        self.log = log

    def _call(self, action: str, args: dict[str, Any], start: Callable[[], Job]) -> Job:
        self.log.add(ActionRecord(self.clock.now(), self.tree, action, args))
        try:
            return start()
        except Exception as error:  # a service refusing work is a failed action, not a crash
            return ImmediateJob(error=error)

    def say(self, text: str, *, volume: float | None = None) -> Job:
        args: dict[str, Any] = {"text": text}
        if volume is not None:
            args["volume"] = volume
        return self._call("say", args, lambda: self.services.speech.say(text, volume=volume))

    def set_led(self, color: str, *, seconds: float | None = None) -> Job:
        args: dict[str, Any] = {"color": color}
        if seconds is not None:
            args["seconds"] = seconds
        return self._call("led", args, lambda: self.services.leds.set_color(color, seconds=seconds))

    def move_servo(self, joint: str, angle_deg: float, *, speed_dps: float | None = None) -> Job:
        args: dict[str, Any] = {"joint": joint, "angle_deg": angle_deg}
        if speed_dps is not None:
            args["speed_dps"] = speed_dps
        return self._call(
            "servo", args, lambda: self.services.servos.move(joint, angle_deg, speed_dps=speed_dps)
        )

    def read_sensor(self, sensor: str) -> Job:
        return self._call("read", {"sensor": sensor}, lambda: self.services.sensors.read(sensor))

    def report_result(self, command_id: str, status: str, result: Any = None) -> Job:
        args = {"id": command_id, "status": status, "result": result}
        return self._call(
            "report", args, lambda: self.services.iot.report(command_id, status, result)
        )
