"""A recording's account of the session, as the session events it was made from.

From format 3 on a recording keeps the events themselves (decoded by
:mod:`engine.session.codec`). Earlier formats kept each kind where it fitted (actions in
``actions``, scenario events in ``world``, what was heard or seen and the devices' health
as blackboard keys, the rest in ``events``); :func:`told_events` puts them back together,
in the order they happened, as the same typed events the live run published. The replay
page, ``vest report`` and the exports read a recording through it, so a replay says what
the live view said. Times are seconds since the session started. A format 1 recording
(before ``events`` and outcomes were kept) gives what it has: actions (failed or not),
scenario events (a press among them), what was heard and seen, devices.
"""

from __future__ import annotations

import re
from typing import Any

from engine.blackboard.catalogue import HAND_SHOWN, SPEECH_HEARD
from engine.recording.replay import Recording
from engine.session.blackboard_news import device_of
from engine.session.events import (
    ActionEnded,
    ActionStarted,
    BehaviorsPaused,
    ButtonPressed,
    DeviceChanged,
    HandShown,
    Heard,
    KeyChanged,
    NodeStatus,
    NotListened,
    NotUnderstood,
    Outcome,
    SafetyAction,
    SessionEvent,
    TreeReloaded,
    TurnTaken,
    WorldEvent,
    told_fields,
)

_PRESS = re.compile(r"presses the button '(?P<label>.*)'$")
_FROM_EVENTS_TABLE: dict[str, type[SessionEvent]] = {
    event_type.kind: event_type
    for event_type in (
        TurnTaken,
        SafetyAction,
        ButtonPressed,
        BehaviorsPaused,
        NotUnderstood,
        NotListened,
        TreeReloaded,
    )
}
Ordered = tuple[float, int, int, SessionEvent]
"""(moment, order across tables, order within the table's kind, the event)."""


def _typed(kind: str, at_s: float, tree: str, fields: dict[str, Any]) -> SessionEvent | None:
    event_type = _FROM_EVENTS_TABLE.get(kind)
    if event_type is None:
        return None  # a kind a later vest keeps: not told here
    names = set(told_fields(event_type)) - {"t_s"}
    values = {name: fields[name] for name in names if name in fields}
    if "tree" in names:
        values["tree"] = tree
    if "devices" in values:
        devices = values["devices"]
        if not isinstance(devices, list) or not all(isinstance(d, str) for d in devices):
            return None  # a damaged row is left out, not guessed
        values["devices"] = tuple(devices)
    try:
        return event_type(t_s=at_s, **values)
    except TypeError:  # a field missing: a damaged row is left out, not guessed
        return None


def every_event(recording: Recording) -> list[SessionEvent]:
    """Every event the recording keeps, nodes' statuses and blackboard changes among them,
    in time order (a key's writer is not kept: ``""``)."""
    events: list[SessionEvent] = [
        NodeStatus(
            row["at_s"],
            row["tree"],
            row["version"],
            row["tick"],
            row["node"],
            row["status"],
            row["feedback"],
        )
        for row in recording.table("statuses")
    ]
    for row in recording.table("blackboard"):
        value = recording.json(row["value"])
        events.append(
            KeyChanged(row["at_s"], row["key"], value, row["value"], bool(row["event"]), "")
        )
    events += told_events(recording)
    return sorted(events, key=lambda event: event.t_s)


def told_events(recording: Recording, until_s: float | None = None) -> list[SessionEvent]:
    """Every event the session told, up to ``until_s``, in the order it happened (but the
    nodes' statuses and blackboard changes, which the recording keeps as state)."""
    if recording.format >= 3:
        return recording.session_events(until_s)
    until = float("inf") if until_s is None else until_s
    found: list[Ordered] = []
    for index, action in enumerate(recording.actions(until_s)):
        args = action.args
        found.append(
            (
                action.at_s,
                action.seq,
                index,
                ActionStarted(action.at_s, 0, action.tree, action.action, args),
            )
        )
        if action.outcome in ("failed", "cut") and (action.ended_s or action.at_s) <= until:
            ended = action.ended_s if action.ended_s is not None else action.at_s
            outcome: Outcome = "cut" if action.outcome == "cut" else "failed"
            event = ActionEnded(
                ended, 0, action.tree, action.action, args, action.at_s, outcome, action.why
            )
            found.append((ended, action.ended_seq, index, event))
    for at, kind, description, seq in recording.ordered_rows(
        "world", "at_s, kind, description", until
    ):
        press = _PRESS.match(description) if kind in ("press", "button") else None
        world: SessionEvent = (
            ButtonPressed(at, press.group("label"), "scenario")
            if press is not None
            else WorldEvent(at, kind, description)
        )
        found.append((at, seq, 0, world))
    for at, seq, kind, tree, fields in recording.events(until_s):
        typed = _typed(kind, at, tree, fields)
        if typed is not None:
            found.append((at, seq, 0, typed))
    found += _from_keys(recording, until)
    found.sort(key=lambda item: (item[0], item[1], item[2]))
    return [event for _, _, _, event in found]


def _from_keys(recording: Recording, until: float) -> list[Ordered]:
    """What was heard and seen, and the devices going offline or back, from the keys."""
    found: list[Ordered] = []
    rows = recording.ordered_rows("blackboard", "at_s, key, value", until)
    ok: dict[str, bool] = {}
    for at, key, text, seq in rows:
        value = recording.json(text)
        if key == SPEECH_HEARD:
            found.append((at, seq, 0, Heard(at, str(value))))
        elif key == HAND_SHOWN and isinstance(value, int):
            found.append((at, seq, 0, HandShown(at, value)))
        device = device_of(key)
        if device is not None and ok.get(device) != bool(value):
            first = device not in ok
            ok[device] = bool(value)
            found.append((at, seq, 0, DeviceChanged(at, device, bool(value), first)))
    return found
