"""Plays a scenario: changes the world at the events' times, as a scheduler hook."""

from __future__ import annotations

import heapq
import itertools
import threading
from collections.abc import Callable
from typing import Any

from engine.scenario.scenario_file import Scenario, ScenarioEvent
from engine.scenario.world import SIDES, ShownHand, World

Change = Callable[[World], None]


def _touch(pad: int, down: bool) -> Change:
    def change(world: World) -> None:
        world.touched[pad] = down
        world.changed("touch")

    return change


def _force(left_n: float, right_n: float) -> Change:
    def change(world: World) -> None:
        world.force_n.update(left=left_n, right=right_n)
        world.changed("force")

    return change


def _ranges(values: dict[str, float | None]) -> Change:
    def change(world: World) -> None:
        world.range_mm.update(values)
        world.changed("range")

    return change


def _set(attribute: str, value: Any, what: str) -> Change:
    def change(world: World) -> None:
        setattr(world, attribute, value)
        world.changed(what)

    return change


def _take_away(hand: ShownHand) -> Change:
    """The hand is lowered, unless another was held up meanwhile (it stays)."""

    def change(world: World) -> None:
        if world.hand is hand:
            world.hand = None
            world.changed("hand")

    return change


def _happen(kind: str, value: Any) -> Change:
    def change(world: World) -> None:
        world.happened(kind, value)

    return change


def changes_of(event: ScenarioEvent) -> list[tuple[float, Change]]:
    """The world changes one scenario event makes, with their times in seconds."""
    value, at = event.value, event.at_s
    if event.kind == "touch":
        return [
            (at, _touch(value["pad"], True)),
            (at + value["seconds"], _touch(value["pad"], False)),
        ]
    if event.kind == "squeeze":
        return [
            (at, _force(value["left_n"], value["right_n"])),
            (at + value["seconds"], _force(0.0, 0.0)),
        ]
    if event.kind == "obstacle":
        seen = {side: value[f"{side}_mm"] for side in SIDES}
        return [(at, _ranges(seen)), (at + value["seconds"], _ranges(dict.fromkeys(SIDES)))]
    if event.kind == "temperature":
        return [(at, _set("temperature_c", value["c"], "temperature"))]
    if event.kind == "ultrasound":
        return [
            (at, _set("ultrasound_cm", value["cm"], "ultrasound")),
            (at + value["seconds"], _set("ultrasound_cm", None, "ultrasound")),
        ]
    if event.kind == "gesture":
        return [(at, _happen("gesture", value))]
    if event.kind in ("unplug", "fault"):
        return [(at, _happen(event.kind, dict(value)))]
    if event.kind in ("hear", "echo"):
        return [(at, _happen(event.kind, dict(value)))]
    if event.kind == "show_hand":
        seed = round(at * 1000) * 8 + (value["fingers"] if value["fingers"] is not None else 7)
        held_at = (value["at"][0], value["at"][1]) if value["at"] is not None else None
        hand = ShownHand(
            value["fingers"], value["image"], value["video"], seed, held_at, value["width_px"]
        )
        gone = at + value["seconds"]
        return [(at, _set("hand", hand, "hand")), (gone, _take_away(hand))]
    if event.kind == "press":
        return [(at, _happen("press", {"button": value}))]
    if event.kind == "cloud":
        command = {"id": value["id"], "type": value["type"], "args": value["args"] or {}}
        return [(at, _happen("cloud", command))]
    raise ValueError(f"no world change for event {event.kind!r}")


class ScenarioPlayer:
    """Applies a scenario's changes to ``world`` when the clock reaches them.

    Times are relative to ``start_s``. ``on_event`` hears each scenario event as it
    starts (for the timeline).
    """

    def __init__(
        self,
        scenario: Scenario,
        world: World,
        *,
        start_s: float = 0.0,
        on_event: Callable[[float, ScenarioEvent], None] | None = None,
    ) -> None:
        self.scenario = scenario
        self.world = world
        self.start_s = start_s
        self.on_event = on_event
        self._order = itertools.count()
        self._pending: list[tuple[float, int, Change, ScenarioEvent | None]] = []
        self._lock = threading.Lock()  # add() comes from a page's request, any thread
        for event in scenario.events:
            self.add(event)

    def add(self, event: ScenarioEvent) -> None:
        """Play ``event`` too, at its ``at_s`` (seconds from ``start_s``; one already past
        is played at the next call)."""
        with self._lock:
            for index, (at, change) in enumerate(changes_of(event)):
                announce = event if index == 0 else None
                heapq.heappush(self._pending, (at, next(self._order), change, announce))

    def __call__(self, now_s: float) -> None:
        self.advance_to(now_s)

    def advance_to(self, now_s: float) -> None:
        """Apply every change due at or before ``now_s`` (clock seconds), in order."""
        elapsed = now_s - self.start_s
        while True:
            with self._lock:
                if not self._pending or self._pending[0][0] > elapsed + 1e-9:
                    return
                at, _, change, event = heapq.heappop(self._pending)
            if event is not None and self.on_event is not None:
                self.on_event(self.start_s + at, event)
            change(self.world)

    @property
    def finished(self) -> bool:
        return not self._pending
