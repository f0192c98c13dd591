"""The therapist's buttons at run time (wizard of oz).

A press comes from the buttons page (any thread), a key on the page, a scenario, or the
cloud's page (engine/view/cloud_session.py: a therapist in another room); it is
carried out between ticks by the scheduler hook :meth:`Wizard.__call__`:

- a button that acts (say, led, move, play) runs on the buttons' own tree, which ticks
  first and outranks every tree: a behavior holding what the press needs (the speaker,
  the face LEDs, a joint) is halted cleanly (joints to rest, LEDs off) when the press
  asks for it; behaviors that only wait (a game waiting for a hand) go on. It is answered
  within one tick of that tree (50 ms). A new press replaces what an earlier press was
  still doing;
- a button that is not shown now (its ``when`` does not hold) is not carried out: the
  page cannot press it, and a scenario's or another client's press of it is told so;
- ``pause`` halts every autonomous tree and keeps them from ticking until ``resume``;
  ``stop`` also halts what a button started.

Every press is published on the robot's session stream (a
:class:`~engine.session.events.ButtonPressed`: the timeline, the recording, the report and
the live view show it), and so are pauses and resumes.
Which buttons show depends on what the robot is doing; the page hears the set whenever it
changes (:meth:`subscribe`).
"""

from __future__ import annotations

import dataclasses
import queue
import threading
from typing import Any

from engine.buttons.button_file import Button, ButtonBoard, When
from engine.loader.tree_definition import TreeDefinition
from engine.runtime.robot import Robot
from engine.runtime.scheduler import RunningTree
from engine.session.events import BehaviorsPaused, ButtonPressed, PressedBy
from engine.web.broadcast import Broadcast

PAGE_QUEUE = 16
"""State updates a page may fall behind by before it is sent only the newest."""


class Wizard:
    """The buttons of ``board`` on ``robot``, on a tree of their own named ``buttons``."""

    def __init__(self, board: ButtonBoard, robot: Robot) -> None:
        self.board = board
        self.robot = robot
        self.idle = board.idle
        self.autonomous = list(robot.trees)
        # priority 100: first in each step, so a press takes what it needs before the
        # behaviors it halted tick again (and yield)
        self.tree: RunningTree = robot.add_tree(board.idle)
        self.paused = False
        self.doing: Button | None = None
        self.presses = 0
        self._pressed: queue.SimpleQueue[tuple[int, PressedBy, str]] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self.states: Broadcast[dict[str, Any]] = Broadcast(robot.clock, PAGE_QUEUE)
        """Each new state, for the pages' streams (the state now: :meth:`state`)."""
        self._begun = False  # the button's tree has ticked since it was pressed
        self._state: dict[str, Any] = self._current_state()

    # -- from any thread ----------------------------------------------------------------------
    def press(self, number: int, *, by: PressedBy = "page", who: str = "") -> Button | None:
        """Queue a press of button ``number`` for the next step; None when there is none.
        ``who``: the account that pressed it from the cloud ("" for a press here)."""
        button = self.board.button(number)
        if button is not None:
            self._pressed.put((number, by, who))
        return button

    def press_label(self, label: str, *, by: PressedBy = "scenario") -> Button | None:
        for button in self.board.buttons:
            if button.label == label:
                return self.press(button.number, by=by)
        return None

    def state(self) -> dict[str, Any]:
        """What the page shows: the buttons shown, whether paused, what a button does now."""
        with self._lock:
            return dict(self._state)

    def close(self) -> None:
        """Tell every page the session ended."""
        self.states.publish({"ended": True})
        self.states.close()

    # -- a scenario's presses ---------------------------------------------------------------
    def world_changed(self, world: Any, what: str) -> None:
        """Nothing in the world presses a button."""

    def world_event(self, kind: str, value: Any) -> None:
        if kind == "press":
            self.press_label(value["button"])

    # -- the scheduler hook -------------------------------------------------------------------
    def __call__(self, now_s: float) -> None:
        while True:
            try:
                number, by, who = self._pressed.get_nowait()
            except queue.Empty:
                break
            self._carry_out(self.board.buttons[number], now_s, by, who)
        if self.paused:  # the operator is told at once, not left waiting
            self.robot.refuse_commands(self.autonomous, "the therapist paused the behaviors")
        status = self.tree.status.name
        if self.doing is not None and status != "INVALID":
            self._begun = True
        # done, or cut short after it began (a person spoke over it): it idles again, and
        # never says its phrase again from the top over the person
        if self.doing is not None and (
            status in ("SUCCESS", "FAILURE") or (status == "INVALID" and self._begun)
        ):
            self._swap(self.idle)
            self.doing = None
        self._publish()

    def _carry_out(self, button: Button, now_s: float, by: PressedBy, who: str) -> None:
        self.presses += 1
        shown = self._shown(button)
        control = button.control or ""
        self.robot.session.publish(ButtonPressed(now_s, button.label, by, shown, control, who))
        if not shown:
            return
        if button.control == "pause":
            self._pause(True)
        elif button.control == "resume":
            self._pause(False)
        elif button.control == "stop":
            self._pause(True)
            self.tree.halt(f"the therapist pressed {button.label!r}")
            self._swap(self.idle)
            self.doing = None
        elif button.tree is not None:
            self._swap(button.tree)  # what it needs it takes from whoever holds it
            self.doing, self._begun = button, False

    def _pause(self, paused: bool) -> None:
        if paused == self.paused:
            return
        self.paused = paused
        for tree in self.autonomous:
            if paused:
                tree.halt("the therapist paused the behaviors")
            else:  # afresh: what happened while paused (a pat, a word) is not answered late
                tree.replace(dataclasses.replace(tree.definition))
            tree.paused = paused
        self.robot.session.publish(BehaviorsPaused(self.robot.clock.now(), paused))

    def _swap(self, definition: TreeDefinition) -> None:
        self.tree.swap(definition, definition.build(self.tree.context))

    # -- what the page shows ----------------------------------------------------------------
    def _shown(self, button: Button) -> bool:
        when = button.when
        if when is None:
            if button.control == "pause":
                return not self.paused
            if button.control == "resume":
                return self.paused
            return True
        return self._holds(when)

    def _holds(self, when: When) -> bool:
        if when.running is not None:
            return any(
                t.name == when.running and t.status.name == "RUNNING" for t in self.autonomous
            )
        if when.paused is not None:
            return self.paused == when.paused
        value = self.robot.blackboard.get(when.key or "")
        if value is None:
            return False
        try:
            return bool(
                {
                    "equals": lambda: value == when.value,
                    "not_equals": lambda: value != when.value,
                    "above": lambda: value > when.value,
                    "below": lambda: value < when.value,
                }[when.comparison or "equals"]()
            )
        except TypeError:  # a value of another kind than the comparison's
            return False

    def _current_state(self) -> dict[str, Any]:
        return {
            "shown": [b.number for b in self.board.buttons if self._shown(b)],
            "paused": self.paused,
            "doing": self.doing.label if self.doing is not None else None,
        }

    def _publish(self) -> None:
        state = self._current_state()
        with self._lock:
            if state == self._state:
                return
            self._state = state
        self.states.publish(dict(state))
