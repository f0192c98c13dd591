"""The service interfaces tree nodes use. Implementations are injected.

Every method returns at once with a :class:`~engine.services.jobs.Job`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from engine.blackboard.catalogue import NOTHING, Carries
from engine.services.jobs import Job


class Speech(Protocol):
    def say(self, text: str, *, volume: float | None = None, interruptible: bool = True) -> Job:
        """Speak ``text``; ``volume`` is 0..1 (None: the robot's default); a person's voice
        stops it unless not ``interruptible``."""
        ...


class Leds(Protocol):
    def set_color(self, color: str, *, seconds: float | None = None) -> Job:
        """Light the face LEDs: a color name or ``#RRGGBB``; ``seconds`` then back to off."""
        ...


class Servos(Protocol):
    def move(self, joint: str, angle_deg: float, *, speed_dps: float | None = None) -> Job:
        """Move ``joint`` to ``angle_deg`` at ``speed_dps`` degrees/second (None: joint's max)."""
        ...

    def rest_pose(self, joint: str) -> tuple[float, float | None]:
        """Where ``joint`` rests and how fast it goes there after a halt: (deg, deg/s)."""
        ...

    def stop(self, joint: str) -> None:
        """Stop ``joint`` where it is now (a move under way ends there)."""
        ...


ON_REQUEST_SENSORS = ("temperature", "ultrasound")
"""The sensors a tree reads on request (the others are polled onto the blackboard)."""


class Sensors(Protocol):
    def read(self, sensor: str) -> Job:
        """Read an on-request sensor (``temperature``, ``ultrasound``).

        The job's result maps blackboard keys to values, e.g.
        ``{"/sensors/temperature/c": 22.2, "/sensors/temperature/f": 71.96}``.
        """
        ...


class IotResults(Protocol):
    def report(
        self, command_id: str, status: str, result: Any = None, *, carries: Carries = NOTHING
    ) -> Job:
        """Tell the cloud how remote command ``command_id`` ended (succeeded / failed);
        ``carries``: what of a person ``result`` was made from (consent decides whether
        it may leave the robot)."""
        ...


@dataclass
class Services:
    """The set of services one robot offers its trees."""

    speech: Speech
    leds: Leds
    servos: Servos
    sensors: Sensors
    iot: IotResults
