"""The session in words: the sentence each event is told as (timeline, live view, replay).

One place says how an event reads, so the terminal, the page and a replay say the same
thing: ``(who, what)``, e.g. ``("touch_thanks", 'says "Thank you"')``.
"""

from __future__ import annotations

from typing import Any

from engine.session.events import (
    ActionEnded,
    ActionStarted,
    BehaviorsPaused,
    ButtonPressed,
    DeviceChanged,
    HandShown,
    Heard,
    NotListened,
    NotUnderstood,
    SafetyAction,
    SessionEvent,
    SpokenOver,
    TreeReloaded,
    TurnTaken,
    WorldEvent,
)

TOLD_KINDS = (
    WorldEvent.kind,
    ButtonPressed.kind,
    BehaviorsPaused.kind,
    ActionStarted.kind,
    ActionEnded.kind,
    TurnTaken.kind,
    SafetyAction.kind,
    DeviceChanged.kind,
    Heard.kind,
    HandShown.kind,
    NotUnderstood.kind,
    NotListened.kind,
    SpokenOver.kind,
    TreeReloaded.kind,
)
"""The kinds of events told in words (statuses and blackboard keys are shown otherwise)."""


def describe_action(action: str, args: dict[str, Any]) -> str:
    if action == "say":
        return f'says "{args["text"]}"'
    if action == "led" and args["color"] == "off":
        return "turns the face LEDs off" + (" (back to rest)" if args.get("rest") else "")
    if action == "led":
        seconds = f" for {_number(args['seconds'])} s" if args.get("seconds") else ""
        return f"lights the face {args['color']}{seconds}"
    if action == "servo":
        speed = f" at {_number(args['speed_dps'])} deg/s" if args.get("speed_dps") else ""
        rest = " (back to rest)" if args.get("rest") else ""
        return f"turns {args['joint']} to {_number(args['angle_deg'])} deg{speed}{rest}"
    if action == "read":
        return f"reads the {args['sensor']} sensor"
    if action == "report":
        result = f": {args['result']}" if args.get("result") is not None else ""
        return f"reports {args.get('id')} {args.get('status')}{result}"
    return f"{action} {args}"


def _number(value: Any) -> str:
    """A number as the timeline writes it (``30``, ``1.5``); a value the consent gate
    withheld as it says."""
    return f"{value:g}" if isinstance(value, int | float) else str(value)


def event_line(event: SessionEvent) -> tuple[str, str] | None:
    """(who, what) the terminal timeline says of ``event``; None: no line of its own."""
    if isinstance(event, WorldEvent):
        return "world", event.description
    if isinstance(event, ButtonPressed):
        nothing = "" if event.done else ", which is not shown now: nothing done"
        who = "scenario" if event.by == "scenario" else "therapist"
        stops = (
            ": everything stops, and the behaviors stay paused until resumed"
            if event.control == "stop" and event.done
            else ""
        )
        where = f" from the cloud ({event.who})" if event.by == "cloud" else ""
        return who, f"presses the button {event.label!r}{where}{nothing}{stops}"
    if isinstance(event, BehaviorsPaused):
        return "buttons", "pauses the behaviors" if event.paused else "resumes the behaviors"
    if isinstance(event, ActionStarted):
        return event.tree, describe_action(event.action, event.args)
    if isinstance(event, ActionEnded):
        what = describe_action(event.action, event.args)
        if event.outcome == "cut":
            return event.tree, f"cut short: {what}" + (f" ({event.why})" if event.why else "")
        if event.outcome == "failed":
            return event.tree, f"could not: {what} ({event.why})"
        return None
    if isinstance(event, TurnTaken):
        return event.tree, event.text
    if isinstance(event, SafetyAction):
        if event.action == "stopped":
            return "safety", f"stops {event.joint} where it is: {event.why}"
        if event.action == "slowed":
            return "safety", f"slows {event.joint}: {event.why}"
        if event.action == "held":
            return "safety", f"holds {event.joint} where it is: {event.why}"
        return None  # a refusal is said by the action that could not be done
    if isinstance(event, DeviceChanged):
        if event.first:
            return None  # the first report at start-up
        return "vest", f"{event.device} is {'back online' if event.ok else 'offline'}"
    if isinstance(event, Heard):
        return "vest", f"hears {event.text!r}"
    if isinstance(event, HandShown):
        return "vest", f"sees {event.fingers} finger{'' if event.fingers == 1 else 's'} held up"
    if isinstance(event, NotUnderstood):
        return event.tree, f"does not understand {event.text!r}"
    if isinstance(event, NotListened):
        return "vest", f"did not listen: {event.why}"
    if isinstance(event, SpokenOver):
        return event.tree or "vest", f"stops saying {event.saying!r}: a person spoke over it"
    if isinstance(event, TreeReloaded):
        if event.problem:
            return "vest", f"keeps the running {event.tree}: {event.problem}"
        return "vest", f"reloads {event.tree}"
    return None


def tone(event: SessionEvent) -> str:
    """What kind of line an event makes, for a page to style (never by colour alone):
    world, therapist, robot, heard, turn, safety, failed, cut, device, reload."""
    if isinstance(event, WorldEvent):
        return "world"
    if isinstance(event, ButtonPressed | BehaviorsPaused):
        return "therapist"
    if isinstance(event, ActionEnded):
        return "cut" if event.outcome == "cut" else "failed"
    if isinstance(event, TurnTaken | SpokenOver):
        return "turn"
    if isinstance(event, SafetyAction):
        return "safety"
    if isinstance(event, DeviceChanged):
        return "device"
    if isinstance(event, Heard | HandShown | NotUnderstood | NotListened):
        return "heard"
    if isinstance(event, TreeReloaded):
        return "reload"
    return "robot"
