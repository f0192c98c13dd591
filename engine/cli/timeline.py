"""The run's timeline: what happened around the robot and what it did, as readable lines.

The timeline is the robot's own output and never stops the robot: a reader that goes
away (``| head``) ends the run quietly, any other write error (a full disk) is told once
on stderr and the run goes on without its timeline. Text people wrote is shown with
control characters escaped (:func:`engine.cli.output.shown`); ``--json`` lines are strict
JSON: a NaN or infinite number is written as null.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any, TextIO

from engine.blackboard.catalogue import HAND_SHOWN, SPEECH_HEARD
from engine.cli.output import discard, finite_json, reason, shown, tell
from engine.runtime.scheduler import RunningTree
from engine.scenario.scenario_file import ScenarioEvent
from engine.services.actions import ActionRecord


def describe_action(action: str, args: dict[str, Any]) -> str:
    if action == "say":
        return f'says "{args["text"]}"'
    if action == "led" and args["color"] == "off":
        return "turns the face LEDs off" + (" (back to rest)" if args.get("rest") else "")
    if action == "led":
        seconds = f" for {args['seconds']:g} s" if args.get("seconds") else ""
        return f"lights the face {args['color']}{seconds}"
    if action == "servo":
        speed = f" at {args['speed_dps']:g} deg/s" if args.get("speed_dps") else ""
        rest = " (back to rest)" if args.get("rest") else ""
        return f"turns {args['joint']} to {args['angle_deg']:g} deg{speed}{rest}"
    if action == "read":
        return f"reads the {args['sensor']} sensor"
    if action == "report":
        result = f": {args['result']}" if args.get("result") is not None else ""
        return f"reports {args['id']} {args['status']}{result}"
    return f"{action} {args}"


class Timeline:
    """Prints world events and robot actions as they happen, relative to ``start_s``."""

    def __init__(
        self,
        out: TextIO,
        *,
        start_s: float,
        as_json: bool = False,
        on_closed: Callable[[], None] | None = None,
    ) -> None:
        self.out = out
        self.start_s = start_s
        self.as_json = as_json
        self.on_closed = on_closed
        self.closed = False
        self.write_error: OSError | None = None
        """Why the timeline stopped being written, when a write failed (not a closed pipe)."""
        self._device_ok: dict[str, bool] = {}

    def start(self) -> None:
        """Print the header (the run has begun)."""
        if not self.as_json:
            self._write(f"{'t (s)':>8}  {'who':14} what\n")

    def _write(self, text: str) -> None:
        """Write and flush; a reader that went away (``| head``) ends the run quietly, a
        failing output (a full disk) is told once on stderr and the robot carries on."""
        if self.closed:
            return
        try:
            self.out.write(text)
            self.out.flush()
        except BrokenPipeError:
            self.closed = True
            discard(self.out)  # nothing more can reach the reader; keep the exit flush quiet
            if self.on_closed is not None:
                self.on_closed()
        except OSError as error:
            self.closed = True
            self.write_error = error
            discard(self.out)
            tell(
                f"vest run: cannot write the timeline ({reason(error)}); "
                "the robot carries on without it"
            )

    def _json_line(self, record: ActionRecord) -> None:
        shown_record = record.to_json()
        shown_record["t"] = round(record.t - self.start_s, 3)
        # a value JSON has no form for (an object in a result) is shown as its text
        line = json.dumps(finite_json(shown_record), allow_nan=False, default=str)
        self._write(line + "\n")

    def world(self, at_s: float, event: ScenarioEvent) -> None:
        """What happened around the robot; a button press is the therapist's."""
        if not self.as_json:
            who = "therapist" if event.kind in ("press", "button") else "world"
            self._line(at_s, who, event.describe())

    def blackboard_write(self, key: str, value: Any, at_s: float) -> None:
        """Show what the robot heard, the fingers it saw held up, and a device going
        offline or coming back (``/devices/<name>/ok`` changing)."""
        if key == SPEECH_HEARD and not self.as_json:
            self._line(at_s, "vest", f"hears {value!r}")
            return
        if key == HAND_SHOWN and not self.as_json:
            self._line(at_s, "vest", f"sees {value} finger{'' if value == 1 else 's'} held up")
            return
        if self.as_json or not (key.startswith("/devices/") and key.endswith("/ok")):
            return
        previous = self._device_ok.get(key)
        self._device_ok[key] = bool(value)
        if previous is None or previous == bool(value):
            return  # the first report at start-up, or no change
        device = key.removeprefix("/devices/").removesuffix("/ok")
        self._line(at_s, "vest", f"{device} is {'back online' if value else 'offline'}")

    def action(self, record: ActionRecord) -> None:
        if self.as_json:
            self._json_line(record)
        else:
            self._line(record.t, record.tree, describe_action(record.action, record.args))

    def failed(self, record: ActionRecord, error: BaseException) -> None:
        """An action the service could not do: said so, after the line that announced it."""
        if self.as_json:
            self._json_line(record)
        else:
            what = describe_action(record.action, record.args)
            self._line(record.t, record.tree, f"could not: {what} ({record.error})")

    def turn(self, at_s: float, tree: str, what: str) -> None:
        """A tree interrupting, waiting for or yielding to another (one voice at a time)."""
        if not self.as_json:
            self._line(at_s, tree, what)

    def _line(self, at_s: float, who: str, what: str) -> None:
        self._write(f"{at_s - self.start_s:8.2f}  {shown(who):14} {shown(what)}\n")

    def summary(self, trees: list[RunningTree]) -> None:
        if self.as_json:
            return
        self._write(
            f"\n{'tree':14} {'rate':>6} {'ticks':>6} {'tick p50':>9} "
            f"{'tick p99':>9} {'late p99':>9} {'skipped':>7}\n"
        )
        for tree in trees:
            s = tree.stats.summary()
            self._write(
                f"{shown(tree.name):14} {tree.definition.rate_hz:5g}/s {s['ticks']:6d} "
                f"{s['duration_p50_ms']:7.3f}ms {s['duration_p99_ms']:7.3f}ms "
                f"{s['lateness_p99_ms']:7.2f}ms {s['skipped']:7d}\n"
            )
