"""The simulated world around the robot: what is touched, squeezed, seen and said.

Scenario events change the world; listeners turn the world into what the robot senses.
Until simulated chips are wired in, :class:`BlackboardSenses` writes the blackboard
directly, as the pollers would.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    GESTURE_LAST,
    SPEECH_HEARD,
    TOUCH_ANY,
    TOUCH_PADS,
    ULTRASOUND_CM,
    range_key,
)
from engine.services.simulated import temperature_reading

PADS = 12
SIDES = ("left", "center", "right")


@dataclass(frozen=True)
class ShownHand:
    """What is held in front of the simulated camera: a person holding up ``fingers``
    (None: an empty view), or a picture, or a video (absolute paths); a picture may be held
    ``at`` a place in the frame ([x, y] px, its top-left) scaled to ``width_px``."""

    fingers: int | None = None
    image: str | None = None
    video: str | None = None
    seed: int = 0
    at: tuple[int, int] | None = None
    width_px: int | None = None


@dataclass
class World:
    """Physical state, in SI-ish units: newtons, millimetres, degrees Celsius, centimetres."""

    touched: list[bool] = field(default_factory=lambda: [False] * PADS)
    force_n: dict[str, float] = field(default_factory=lambda: {"left": 0.0, "right": 0.0})
    range_mm: dict[str, float | None] = field(default_factory=lambda: dict.fromkeys(SIDES))
    temperature_c: float = 22.0
    ultrasound_cm: float | None = None
    hand: ShownHand | None = None
    listeners: list[WorldListener] = field(default_factory=list)

    def add_listener(self, listener: WorldListener) -> None:
        """``listener`` hears every change and event from now on, after those added before."""
        self.listeners.append(listener)

    def changed(self, what: str) -> None:
        for listener in self.listeners:
            listener.world_changed(self, what)

    def happened(self, kind: str, value: Any) -> None:
        for listener in self.listeners:
            listener.world_event(kind, value)


class WorldListener(Protocol):
    def world_changed(self, world: World, what: str) -> None:
        """``what`` changed: touch, force, range, temperature, ultrasound or hand."""
        ...

    def world_event(self, kind: str, value: Any) -> None:
        """Something happened once: gesture, hear or cloud (a remote command)."""
        ...


EVENT_KEYS = {
    "gesture": GESTURE_LAST,
    "hear": SPEECH_HEARD,
    "cloud": "/iot/inbox",
}


class BlackboardSenses:
    """Stages what the robot would sense straight onto the blackboard (no device models).

    Polled senses (touch, force, range) are staged at once; temperature and ultrasound
    are read on request, so they are only answered through :meth:`readers`.
    """

    def __init__(self, blackboard: Blackboard, world: World) -> None:
        self.blackboard = blackboard
        self.world = world

    def world_changed(self, world: World, what: str) -> None:
        if what == "touch":
            self.blackboard.stage(TOUCH_PADS, list(world.touched))
            self.blackboard.stage(TOUCH_ANY, any(world.touched))
        elif what == "force":
            self.blackboard.stage(FORCE_LEFT_N, world.force_n["left"])
            self.blackboard.stage(FORCE_RIGHT_N, world.force_n["right"])
        elif what == "range":
            for side in SIDES:
                self.blackboard.stage(range_key(side), world.range_mm[side])

    def world_event(self, kind: str, value: Any) -> None:
        key = EVENT_KEYS.get(kind)
        if key is not None:  # unplug and fault concern devices, which this view has none of
            self.blackboard.stage_event(key, value)

    def start(self) -> None:
        """Stage the world's initial state."""
        for what in ("touch", "force", "range"):
            self.world_changed(self.world, what)

    def readers(self) -> dict[str, Any]:
        """On-request sensor readers for :class:`~engine.services.simulated.SimulatedSensors`."""
        return {
            "temperature": lambda: temperature_reading(self.world.temperature_c),
            "ultrasound": lambda: {ULTRASOUND_CM: self.world.ultrasound_cm},
        }
