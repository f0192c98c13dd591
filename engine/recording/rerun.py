"""A recorded session played again against trees that may have changed: what would they
have done? (The py_trees users' wish: replay recorded runs in tests.)

Everything the robot sensed in the recording (every blackboard write but the trees' own
``/vars/``) is staged again at its moment, on a virtual clock, for the trees given; their
actions are compared with the recorded ones. A therapist's edit (a threshold, a phrase)
is then checked against a real session before it meets a child.

The therapist's button presses are not played again: the buttons' own actions, and the
moves back to rest of the trees they interrupted, are left out of the comparison.
A recording keeps only what the person consented to: one that kept no speech as text
(``meta`` ``left_out``) is played again without what was heard, so its dialogs differ.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import (
    TEMPERATURE_C,
    TEMPERATURE_F,
    ULTRASOUND_CM,
    VARIABLES_PREFIX,
    KeyCatalogue,
)
from engine.buttons.button_file import BUTTONS_TREE
from engine.clock import VirtualClock
from engine.recording.replay import RecordedAction, Recording
from engine.runtime.robot import Behaviors, Robot
from engine.services.simulated import simulated_services

TOLERANCE_S = 0.25
"""Two actions of the same tree, kind and arguments this close in time are the same."""


@dataclass(frozen=True)
class ActionDifference:
    """An action only one of the two runs took: ``recorded`` (only then) or ``now``."""

    side: str
    action: RecordedAction

    def __str__(self) -> str:
        a = self.action
        said = "was taken, not now" if self.side == "recorded" else "is taken now, not then"
        return f"{a.at_s:.2f} s {a.tree}: {a.action} {a.args} {said}"


class _Inputs:
    """A scheduler hook staging the recorded writes due by each step."""

    def __init__(self, rows: list[tuple[float, str, object, bool]], board: Blackboard) -> None:
        self.rows, self.board, self.next = rows, board, 0

    def __call__(self, now_s: float) -> None:
        while self.next < len(self.rows) and self.rows[self.next][0] <= now_s + 1e-9:
            _, key, value, event = self.rows[self.next]
            if event:
                self.board.stage_event(key, value)
            else:
                self.board.stage(key, value)
            self.next += 1


def rerun(recording: Recording, behaviors: Behaviors) -> list[RecordedAction]:
    """The actions ``behaviors`` take on what the recording's robot sensed."""
    clock = VirtualClock()
    board = Blackboard(behaviors.loader.catalogue, clock)
    board.reset()
    services = simulated_services(clock, realistic=True, readers=_readers(recording, clock))
    robot = Robot(behaviors, clock=clock, services=services, blackboard=board)
    robot.scheduler.add_hook(_Inputs(_sensed(recording, behaviors.loader.catalogue), board))
    robot.scheduler.run(until_s=recording.duration_s, start_s=0.0)
    return [
        RecordedAction(record.t, record.tree, record.action, record.args, record.error)
        for record in robot.action_log.records
    ]


def _readers(recording: Recording, clock: VirtualClock) -> dict[str, Callable[[], dict[str, Any]]]:
    """On-request sensors that answer what the recorded robot's sensors answered then (the
    reading recorded next after the moment of the read, else the last one)."""

    def answer(keys: tuple[str, ...]) -> Callable[[], dict[str, Any]]:
        histories = {key: recording.key_history(key) for key in keys}

        def read() -> dict[str, Any]:
            now = clock.now()
            reading: dict[str, Any] = {}
            for key, history in histories.items():
                later = [value for at, value in history if at >= now - 1e-9]
                earlier = [value for at, value in history if at < now]
                reading[key] = later[0] if later else (earlier[-1] if earlier else None)
            return reading

        return read

    return {
        "temperature": answer((TEMPERATURE_C, TEMPERATURE_F)),
        "ultrasound": answer((ULTRASOUND_CM,)),
    }


def _sensed(recording: Recording, catalogue: KeyCatalogue) -> list[tuple[float, str, object, bool]]:
    """Every reading recorded, in time order: (moment, key, value, whether an event). A
    number recorded as null (JSON has no NaN: engine.session.json_values) was a reading that
    could not be trusted, and is NaN again, as the trees saw it."""
    rows = []
    for key in recording.keys_like("%"):
        if key.startswith(VARIABLES_PREFIX):
            continue
        event = recording.is_event(key)
        spec = catalogue.lookup(key)
        number = spec is not None and spec.value_type is float
        rows += [
            (at, key, math.nan if number and value is None else value, event)
            for at, value in recording.key_history(key)
        ]
    return sorted(rows, key=lambda row: row[0])


def _compared(action: RecordedAction) -> bool:
    """Whether the trees' own logic took ``action`` (not a button, not a rest after a halt)."""
    return action.tree != BUTTONS_TREE and not action.args.get("rest")


def compare(
    recorded: list[RecordedAction], now: list[RecordedAction], tolerance_s: float = TOLERANCE_S
) -> list[ActionDifference]:
    """The actions only one side took, in time order (empty: the trees act as before)."""
    unmatched = [action for action in now if _compared(action)]
    differences = []
    for action in filter(_compared, recorded):
        match = next(
            (
                other
                for other in unmatched
                if other.tree == action.tree
                and other.action == action.action
                and other.args == action.args
                and abs(other.at_s - action.at_s) <= tolerance_s
            ),
            None,
        )
        if match is None:
            differences.append(ActionDifference("recorded", action))
        else:
            unmatched.remove(match)
    differences += [ActionDifference("now", action) for action in unmatched]
    return sorted(differences, key=lambda d: d.action.at_s)
