"""On-request readings reach the blackboard the way polled ones do: staged by the service.

A tree asks for a temperature or an ultrasound range and waits; the reading is staged onto
the blackboard by the sensor service, never written by the tree (trees write only
``/vars/``), and every tree sees it from the next commit on, under the keys the robot
config maps it to. :func:`with_staged_readings` wraps a robot's sensor service so.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from engine.blackboard.board import Blackboard
from engine.services.interfaces import Sensors, Services
from engine.services.jobs import Job


class _StagingJob:
    """A read whose values are staged the first time it is seen done."""

    def __init__(self, job: Job, blackboard: Blackboard) -> None:
        self._job = job
        self._blackboard = blackboard
        self._staged = False

    def done(self) -> bool:
        finished = self._job.done()
        if finished and not self._staged:
            self._staged = True
            result = self._job.result() if self._job.error() is None else None
            if isinstance(result, Mapping):
                for key, value in result.items():
                    self._blackboard.stage(key, value)
        return finished

    def error(self) -> BaseException | None:
        return self._job.error()

    def result(self) -> Any:
        return self._job.result()

    def cancel(self) -> None:
        self._job.cancel()


class StagingSensors:
    """A :class:`~engine.services.interfaces.Sensors` whose readings are staged."""

    def __init__(self, sensors: Sensors, blackboard: Blackboard) -> None:
        self.sensors = sensors
        self.blackboard = blackboard

    def read(self, sensor: str) -> Job:
        """The wrapped read; its result (key -> value) is staged when it is done."""
        return _StagingJob(self.sensors.read(sensor), self.blackboard)


def with_staged_readings(services: Services, blackboard: Blackboard) -> Services:
    """``services`` whose sensor readings are staged onto ``blackboard``."""
    if isinstance(services.sensors, StagingSensors):
        return services
    return dataclasses.replace(services, sensors=StagingSensors(services.sensors, blackboard))
