"""Services that tree nodes call: speech, LEDs, servos, sensor reads, IoT results.

Nodes never talk to a service directly: they go through :class:`TreeActions`, which
records every call (for the timeline, ``--json`` output and tests) and returns a
:class:`Job` the node polls without blocking the tick.
"""

from engine.services.actions import ActionLog, ActionRecord, TreeActions
from engine.services.interfaces import IotResults, Leds, Sensors, Services, Servos, Speech
from engine.services.jobs import FutureJob, ImmediateJob, Job, TimedJob

__all__ = [
    "ActionLog",
    "ActionRecord",
    "FutureJob",
    "ImmediateJob",
    "IotResults",
    "Job",
    "Leds",
    "Sensors",
    "Services",
    "Servos",
    "Speech",
    "TimedJob",
    "TreeActions",
]
