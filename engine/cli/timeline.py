"""The run's timeline: what happened around the robot and what it did, as readable lines.

A reader of the session stream (:mod:`engine.session.events`): each event worth a line
becomes one, in the terminal or, with ``--json``, as one JSON object with its ``event``
kind (see docs/view-and-recordings.md). The timeline is the robot's own output and never
stops the robot: a reader that goes away (``| head``) ends the run quietly, any other
write error (a full disk) is told once on stderr and the run goes on without its
timeline. Text people wrote is shown with control characters escaped
(:func:`engine.cli.output.shown`); ``--json`` lines are strict JSON: a NaN or infinite
number is written as null.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TextIO

from engine.cli.output import discard, reason, shown, tell
from engine.runtime.scheduler import RunningTree
from engine.session.codec import encode
from engine.session.events import ActionEnded, DeviceChanged, SessionEvent
from engine.session.json_values import json_text
from engine.session.sentences import TOLD_KINDS, event_line


def event_json(event: SessionEvent, start_s: float) -> dict[str, Any] | None:
    """``event`` as one ``--json`` object: its message (:mod:`engine.session.codec`, times
    in seconds since ``start_s``) with its kind named ``event``; None for the events the
    timeline does not show."""
    if event.kind not in TOLD_KINDS:
        return None  # a status, a key: shown otherwise
    if isinstance(event, ActionEnded) and event.outcome == "done":
        return None  # an action's line says it began; only one that did not end well is told
    if isinstance(event, DeviceChanged) and event.first:
        return None  # the first report at start-up
    message = encode(event, start_s)
    return {"t": message.pop("t"), "event": message.pop("kind"), **message}


class Timeline:
    """Prints the session's events as they happen, relative to ``start_s``: a session
    reader (``on_event``)."""

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

    def on_event(self, event: SessionEvent) -> None:
        if self.as_json:
            shown_event = event_json(event, self.start_s)
            if shown_event is not None:
                # a value JSON has no form for (an object in a result) is shown as its text
                text = json_text(shown_event)
                self._write(text + "\n")
            return
        line = event_line(event)
        if line is not None:
            who, what = line
            self._write(f"{event.t_s - self.start_s:8.2f}  {shown(who):14} {shown(what)}\n")

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
