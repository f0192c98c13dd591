"""Commands from a ROS 2 graph (``vest run --ros2 --ros2-commands``), taken the cloud's way.

A ``std_msgs/String`` on ``/vest/command`` holds ``{"type", "args", "id"}``: checked as the
cloud service checks an operator's command (:func:`~engine.remote_commands.command_problem`),
then staged on ``/iot/inbox`` for the iot_command tree, which checks it again and carries it
out inside the safety envelope. Never raw actuator access. How each one stands is told on
``/vest/command/result`` under the sender's id (``{"id", "status", "result"}``):

- ``RECEIVED``: taken, handed to the iot_command tree;
- ``SUCCEEDED`` / ``FAILED``: how the tree ended it, with its result (a reading only where
  the person's consent lets readings leave the robot);
- ``REFUSED``: never carried out, with why (malformed, arguments the robot would refuse,
  an id already waiting, too many waiting);
- ``LOST``: no result came in 65 s, or the robot stopped first.
"""

from __future__ import annotations

import json
import logging
import re
import threading
from collections.abc import Callable
from typing import Any

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import IOT_INBOX
from engine.clock import Clock
from engine.privacy.consent_gate import RESULT_WITHHELD, ConsentGate
from engine.remote_commands import COMMAND_TYPES, command_problem
from engine.session.events import ActionStarted
from engine.session.json_values import json_value

log = logging.getLogger(__name__)
AT_MOST_WAITING = 8
"""Commands from the graph carried out or waiting at once; more are refused (a flood)."""
WAITING_AT_MOST_S = 65.0
"""A command whose result has not come in this long is told LOST (CarryOut gives up after
60 s; a tree cut off never reports)."""
AT_MOST_BYTES = 64 * 1024
"""The longest command taken (a say is at most 1000 characters)."""
AT_MOST_DEPTH = 8
"""The deepest nesting of JSON a command may have (its args are one level deep)."""
WARN_EVERY_S = 10.0
"""Refusals are logged once per this many seconds (a flood does not fill the log)."""
_GIVEN_ID = re.compile(r"[A-Za-z0-9_.:-]{1,64}")
PREFIX = "ros2:"

Tell = Callable[[str | None, str, Any], None]
"""(the sender's id, or None; status; result): published on the result topic."""


class RefusedError(ValueError):
    """A command that is not carried out; the message says why."""


def parse_command(text: str) -> tuple[str | None, str, dict[str, Any]]:
    """(the sender's id or None, type, args) of a command's JSON text; RefusedError with why."""
    if len(text) > AT_MOST_BYTES:
        raise RefusedError(f"a command is at most {AT_MOST_BYTES} characters")
    if _depth(text) > AT_MOST_DEPTH:
        raise RefusedError(f"a command nests at most {AT_MOST_DEPTH} levels")
    try:
        command = json.loads(text)
    except ValueError as error:
        raise RefusedError(f"not JSON ({error})") from None
    if not isinstance(command, dict):
        raise RefusedError('a command is a JSON object: {"type": "say", "args": {...}}')
    given = command.get("id")
    if given is not None and not (isinstance(given, str) and _GIVEN_ID.fullmatch(given)):
        raise RefusedError("id: 1 to 64 letters, digits and _ . : -")
    kind, args = command.get("type"), command.get("args", {})
    if kind not in COMMAND_TYPES:
        raise RefusedError(f"type: one of {', '.join(COMMAND_TYPES)}")
    if not isinstance(args, dict):
        raise RefusedError("args: a JSON object")
    problem = command_problem(kind, args)
    if problem is not None:
        raise RefusedError(problem)
    return given, str(kind), args


def _depth(text: str) -> int:
    """How deep brackets nest in ``text`` (strings aside): before parsing, so a hostile
    command cannot exhaust the parser's recursion."""
    depth = deepest = 0
    in_string = escaped = False
    for char in text:
        if in_string:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                in_string = False
        elif char == '"':
            in_string = True
        elif char in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif char in "]}":
            depth -= 1
    return deepest


class GraphCommands:
    """The commands taken from the graph and not yet answered."""

    def __init__(self, clock: Clock, tell: Tell, *, gate: ConsentGate) -> None:
        """``gate``: what may leave the robot (a result made of readings, say)."""
        self.clock, self._tell = clock, tell
        self.gate = gate
        self.blackboard: Blackboard | None = None
        self._waiting: dict[str, float] = {}  # our id -> when it was staged (clock s)
        self._lock = threading.Lock()
        self._count = 0
        self._warned_s = -WARN_EVERY_S
        self.refused = 0

    def received(self, text: str) -> None:
        """A command's text (Zenoh's thread): staged, or refused at once."""
        try:
            given, kind, args = parse_command(text)
        except RefusedError as refusal:
            self.refuse(None, str(refusal))
            return
        with self._lock:
            self._count += 1
            command_id = PREFIX + (given or f"n{self._count}")
            if command_id in self._waiting:
                why = "a command with this id is still waiting for its result"
            elif len(self._waiting) >= AT_MOST_WAITING:
                why = f"busy: {AT_MOST_WAITING} commands are already waiting"
            else:
                why = ""
                self._waiting[command_id] = self.clock.now()
        if why or self.blackboard is None:
            self.refuse(given, why or "the robot is not running yet")
            return
        self.blackboard.stage_event(IOT_INBOX, {"id": command_id, "type": kind, "args": args})
        self._tell(command_id.removeprefix(PREFIX), "RECEIVED", None)

    def refuse(self, given: str | None, why: str) -> None:
        self.refused += 1
        now_s = self.clock.now()
        if now_s - self._warned_s >= WARN_EVERY_S:
            self._warned_s = now_s
            log.warning("ros2: a command was refused (%d so far): %s", self.refused, why)
        self._tell(given, "REFUSED", {"error": why})

    def reported(self, event: ActionStarted) -> None:
        """The iot_command tree reported a command: told, when it came from the graph."""
        command_id = str(event.args.get("id", ""))
        with self._lock:
            if self._waiting.pop(command_id, None) is None:
                return  # the cloud's, or a scenario's
        result = event.args.get("result")
        status = str(event.args.get("status", "")).upper()
        if not self.gate.lets_result_out(result, event.carries):
            status, result = "FAILED", {"error": RESULT_WITHHELD}
        self._tell(command_id.removeprefix(PREFIX), status, json_value(result))

    def sweep(self) -> None:
        """Commands waiting too long are told LOST (every second, beside the robot)."""
        now_s = self.clock.now()
        with self._lock:
            lost = [key for key, at_s in self._waiting.items() if now_s - at_s > WAITING_AT_MOST_S]
            for command_id in lost:
                del self._waiting[command_id]
        why = f"no result in {WAITING_AT_MOST_S:.0f} s: is the iot_command tree running?"
        for command_id in lost:
            self._tell(command_id.removeprefix(PREFIX), "LOST", {"error": why})

    def stopped(self) -> None:
        """The robot stops: every command still waiting is told LOST."""
        with self._lock:
            lost, self._waiting = list(self._waiting), {}
        for command_id in lost:
            why = "the robot stopped before it was done"
            self._tell(command_id.removeprefix(PREFIX), "LOST", {"error": why})
