"""A recorded session as a therapist reads it (``vest report FILE``): one static HTML page.

Who, when and with which profile; what the person did (touched, hugged, waved, said,
showed fingers), what the therapist did (the buttons pressed) and how the robot answered,
with how long it took, one line each (a sentence it did not understand is answered as
such; a time it could not listen because it was speaking is a line of its own); how often
each behaviour acted; what the robot did not understand; devices that dropped out; and the
sensors over the session, drawn as inline SVG. Everything comes from the recording's
account of the session (:mod:`engine.recording.told`), its blackboard and actions, so a
session on the robot reads the same as one on the simulated vest. Printable on A4.
"""

from __future__ import annotations

import datetime
import html
import json
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    GESTURE_LAST,
    HAND_SHOWN,
    IOT_INBOX,
    RANGE_CENTER_MM,
    SPEECH_HEARD,
    TOUCH_ANY,
)
from engine.buttons.button_file import BUTTONS_TREE
from engine.recording.replay import RecordedAction, Recording
from engine.recording.report_plots import numbers, plot
from engine.recording.told import told_events
from engine.session.events import ButtonPressed, NotListened, NotUnderstood

ANSWER_WITHIN_S = 10.0
"""An action this soon after what the person did counts as the robot's answer."""
PRESSED_N = 1.0
"""Force on a side pad above which the person is pressing it."""


@dataclass(frozen=True)
class Moment:
    """Something someone did (``who``: the person, the therapist, the operator), and the
    robot's answer: the actions of the first tree that acted after it and before the next
    thing anyone did (none: no answer). ``not_understood`` is what the robot heard and
    had no rule for; ``not_listened`` says the robot could not listen (it was speaking)."""

    at_s: float
    did: str
    answers: tuple[RecordedAction, ...]
    who: str = "the person"
    not_understood: str | None = None
    not_listened: bool = False

    @property
    def answer(self) -> RecordedAction | None:
        return self.answers[0] if self.answers else None

    @property
    def response_s(self) -> float | None:
        return None if self.answer is None else self.answer.at_s - self.at_s


def _rows(recording: Recording, key: str) -> list[tuple[float, Any]]:
    return recording.key_history(key)


PERSON_EVENTS = ("touch", "squeeze", "gesture", "hear", "show_hand", "obstacle")
"""Scenario events that are the person doing something (not a device failing)."""


def person_moments(recording: Recording) -> list[Moment]:
    """What the person, the therapist and the operator did, in order, each with the
    robot's first answer: a simulated session's scenario events (so an answer's time
    counts from the act itself), else what the sensors and the recognizer saw; the
    therapist's presses; each time the robot could not listen."""
    told = told_events(recording)
    done: list[tuple[float, str, str, str]] = [
        (at, "the person", description, kind)
        for at, kind, description in recording.world()
        if kind in PERSON_EVENTS
    ]
    done += [
        (at, "the operator", description.removeprefix("operator "), kind)
        for at, kind, description in recording.world()
        if kind == "cloud"
    ]
    if not done:
        done = sensed(recording)
    done += [
        (event.t_s, "the therapist", f"pressed the button \u201c{event.label}\u201d", "press")
        for event in told
        if isinstance(event, ButtonPressed)
    ]
    done += [
        (event.from_s, "the person", "spoke while the robot was speaking", "not_listened")
        for event in told
        if isinstance(event, NotListened)
    ]
    misunderstood = [event for event in told if isinstance(event, NotUnderstood)]
    actions = recording.actions()
    reporting = {a.tree for a in actions if a.action == "report"}
    ordered = sorted(done, key=lambda item: item[0])
    moments = []
    for index, (at, who, did, kind) in enumerate(ordered):
        if kind == "not_listened":  # a line of its own: nothing to answer
            moments.append(Moment(at, did, (), who, not_listened=True))
            continue
        later = [  # the next thing the same one did ends the wait for an answer
            t for t, w, _, k in ordered[index + 1 :] if t > at and w == who and k != "not_listened"
        ]
        until = min([at + ANSWER_WITHIN_S, *later])
        window = [a for a in actions if at <= a.at_s < until and _answers(who, a, reporting)]
        tree = window[0].tree if window else None
        answers = tuple(a for a in window if a.tree == tree)[:3]
        heard = next(
            (e.text for e in misunderstood if at <= e.t_s < until and kind == "hear"), None
        )
        moments.append(Moment(at, did, answers, who, heard))
    return moments


def _answers(who: str, action: RecordedAction, reporting: set[str]) -> bool:
    """Whether ``action`` can be the answer to something ``who`` did: a press is answered
    by the buttons, an operator's command by the trees that report commands
    (``reporting``), the person by the other trees."""
    if who == "the therapist":
        return action.tree == BUTTONS_TREE
    if who == "the operator":
        return action.tree in reporting
    return action.tree != BUTTONS_TREE and action.tree not in reporting


def sensed(recording: Recording) -> list[tuple[float, str, str, str]]:
    """What the person (and the operator) did as the robot sensed it (on a robot in a real
    room): (moment, who, what, the kind of scenario event it would be)."""
    done: list[tuple[float, str, str]] = []
    was_touched = False
    for at, touched in _rows(recording, TOUCH_ANY):
        if touched and not was_touched:
            done.append((at, "touched the vest", "touch"))
        was_touched = bool(touched)
    left = dict(_rows(recording, FORCE_LEFT_N))
    right = dict(_rows(recording, FORCE_RIGHT_N))
    pressing = False
    level = {"left": 0.0, "right": 0.0}
    for at in sorted(set(left) | set(right)):
        level["left"] = float(left.get(at, level["left"]) or 0.0)
        level["right"] = float(right.get(at, level["right"]) or 0.0)
        now = level["left"] > PRESSED_N or level["right"] > PRESSED_N
        if now and not pressing:
            both = level["left"] > PRESSED_N and level["right"] > PRESSED_N
            what = "hugged the robot" if both else "pressed a side"
            done.append(
                (
                    at,
                    f"{what} ({level['left']:.1f} N left, {level['right']:.1f} N right)",
                    "squeeze",
                )
            )
        pressing = now
    for at, gesture in _rows(recording, GESTURE_LAST):
        done.append((at, f"made a gesture: {gesture}", "gesture"))
    for at, text in _rows(recording, SPEECH_HEARD):
        done.append((at, f"said \u201c{text}\u201d", "hear"))
    for at, fingers in _rows(recording, HAND_SHOWN):
        done.append((at, f"showed {fingers} finger{'' if fingers == 1 else 's'}", "show_hand"))
    found = [(at, "the person", what, kind) for at, what, kind in done]
    for at, command in _rows(recording, IOT_INBOX):
        kind = command.get("type", "?") if isinstance(command, dict) else command
        found.append((at, "the operator", f"sent {kind}", "cloud"))
    return found


def not_understood(recording: Recording) -> list[tuple[float, str]]:
    """(moment, what the robot heard) for each utterance no dialog rule matched, once
    each (a format 1 recording: read from the dialog node's feedback)."""
    if recording.format >= 2:
        return [
            (event.t_s, event.text)
            for event in told_events(recording)
            if isinstance(event, NotUnderstood)
        ]
    found: list[tuple[float, str]] = []
    last: tuple[float, str] | None = None
    for at, feedback in recording.feedback_containing("no rule matches "):
        if last is not None and last[1] == feedback and at - last[0] <= ANSWER_WITHIN_S:
            continue  # the same node's next status (RUNNING, then done) says it again
        last = (at, feedback)
        found.append((at, feedback.split("no rule matches ", 1)[1].split(": ", 1)[0]))
    return found


def outages(recording: Recording) -> list[tuple[str, float, float | None]]:
    """(device, offline at, back at or None) for each time a device dropped out."""
    found: list[tuple[str, float, float | None]] = []
    for key in recording.keys_like("/devices/%/ok"):
        device = key.removeprefix("/devices/").removesuffix("/ok")
        since: float | None = None
        for at, ok in _rows(recording, key):
            if ok is False and since is None:
                since = at
            elif ok is True and since is not None:
                found.append((device, since, at))
                since = None
        if since is not None:  # to the end (from the start: never there, or no model)
            found.append((device, since, None))
    return sorted(found, key=lambda item: item[1])


def _lasted(since: float, back: float | None) -> str:
    if back is None:
        return "the whole session" if since < 0.5 else "until the end"
    return f"{back - since:.1f} s"


def _answer_text(action: RecordedAction) -> str:
    cut = " (cut short)" if action.cut else ""
    return _action_text(action) + cut


def _action_text(action: RecordedAction) -> str:
    args = action.args
    if action.action == "say":
        return f"said \u201c{args.get('text', '')}\u201d"
    if action.action == "led":
        return f"lit its face {args.get('color', '')}"
    if action.action == "servo":
        return f"turned its {args.get('joint', '')} to {args.get('angle_deg', ''):g} deg"
    if action.action == "read":
        return f"read its {args.get('sensor', '')} sensor"
    if action.action == "report":
        return f"told the operator the command {args.get('status', '')}"
    return f"{action.action} {json.dumps(args)}"


def _answer_cell(moment: Moment) -> tuple[str, str]:
    """The robot's answer to ``moment`` as the report shows it (HTML), and its delay."""
    if moment.not_listened:
        return '<span class="none">could not listen: it was speaking</span>', "-"
    if moment.answer is None and moment.not_understood is None:
        return '<span class="none">no answer</span>', "-"
    parts = []
    if moment.not_understood is not None:
        parts.append(f"did not understand \u201c{moment.not_understood}\u201d")
    if moment.answer is not None:
        done = ", ".join(_answer_text(action) for action in moment.answers)
        parts.append(f"{moment.answer.tree}: {done}")
    took = f"{moment.response_s:.2f} s" if moment.response_s is not None else "-"
    return html.escape("; ".join(parts)), took


def _started(epoch: str | None) -> str:
    """When the session was recorded, as a date a person reads (UTC)."""
    try:
        stamp = datetime.datetime.fromtimestamp(float(epoch or ""), tz=datetime.UTC)
    except (ValueError, OverflowError, OSError):
        return "date unknown"
    return stamp.strftime("%d %B %Y, %H:%M UTC")


STYLE = (Path(__file__).resolve().parent / "report.css").read_text
"""The report's style sheet, read when a report is written (it goes inside the page)."""


def report_html(recording: Recording) -> str:
    """The report as one HTML document (no outside files)."""
    end = recording.duration_s
    moments = person_moments(recording)
    answered = [m.response_s for m in moments if m.response_s is not None and not m.not_listened]
    rows = []
    for moment in moments:
        answer, took = _answer_cell(moment)
        rows.append(
            f"<tr><td class='num'>{moment.at_s:.1f} s</td><td>{html.escape(moment.who)}</td>"
            f"<td>{html.escape(moment.did)}</td><td>{answer}</td>"
            f"<td class='num'>{took}</td></tr>"
        )
    rows_html = "".join(rows)
    fired = Counter({tree.name: 0 for tree in recording.trees})
    fired.update(action.tree for action in recording.actions())
    behaviours = "".join(
        f"<tr><td>{html.escape(tree)}</td><td class='num'>{count}</td></tr>"
        for tree, count in fired.most_common()
    )
    missed = "".join(
        f"<tr><td class='num'>{at:.1f} s</td><td>{html.escape(text)}</td></tr>"
        for at, text in not_understood(recording)
    )
    dropped = "".join(
        f"<tr><td>{html.escape(device)}</td><td class='num'>{since:.1f} s</td>"
        f"<td class='num'>{'-' if back is None else f'{back:.1f} s'}</td>"
        f"<td class='num'>{_lasted(since, back)}</td></tr>"
        for device, since, back in outages(recording)
    )
    median = sorted(answered)[len(answered) // 2] if answered else None
    acts = [m for m in moments if not m.not_listened]
    unheard = len(moments) - len(acts)
    summary = (
        f"{len(acts)} things done (by the person, the therapist or an operator); the robot "
        f"answered {len(answered)}"
        + (f", typically within {median:.2f} s" if median is not None else "")
        + "."
        + (
            f" {unheard} time{'s' if unheard != 1 else ''} the person spoke while the robot "
            "was speaking, and it could not listen."
            if unheard
            else ""
        )
    )
    plots = [
        plot(
            "Squeeze on the side pads",
            "N",
            [
                ("left", "#c62828", numbers(_rows(recording, FORCE_LEFT_N))),
                ("right", "#1565c0", numbers(_rows(recording, FORCE_RIGHT_N))),
            ],
            end,
        ),
        plot(
            "Touched",
            "yes = 1",
            [("any pad", "#2e7d32", numbers(_rows(recording, TOUCH_ANY)))],
            end,
        ),
        plot(
            "Someone in front",
            "cm",
            [("center distance", "#6a1b9a", numbers(_rows(recording, RANGE_CENTER_MM), 0.1))],
            end,
        ),
    ]
    meta = recording.meta
    profile = meta.get("profile") or "no profile"
    recorded = html.escape(recording.path.name)
    robot = html.escape(meta.get("robot_config", "?"))
    person = html.escape(meta.get("person") or "no person named")
    when = html.escape(_started(meta.get("started")))
    return "\n".join(
        [
            '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">',
            f"<title>Session report: {recorded}</title>",
            f"<style>{STYLE(encoding='utf-8')}</style></head><body>",
            "<h1>Session report</h1>",
            f'<p class="meta">{when} &middot; {person} &middot; {end:.1f} s &middot; '
            f"profile {html.escape(profile)} &middot; robot {robot} &middot; {recorded}</p>",
            f"<p>{html.escape(summary)}</p>",
            "<h2>What the person did, and how the robot answered</h2>",
            _table(
                ["when", "who", "did", "the robot", "answer after"],
                rows_html,
                "nothing",
                numeric={0, 4},
            ),
            "<h2>How often each behaviour acted</h2>",
            _table(["behaviour", "actions"], behaviours, "none acted", numeric={1}),
            "<h2>What the robot did not understand</h2>",
            _table(["when", "heard"], missed, "everything it heard matched a rule", numeric={0}),
            "<h2>Devices that dropped out</h2>",
            _table(["device", "offline at", "back at", "for"], dropped, "none", numeric={1, 2, 3}),
            "<h2>The sensors over the session</h2>",
            *plots,
            "</body></html>\n",
        ]
    )


def _table(heads: list[str], rows: str, empty: str, *, numeric: set[int]) -> str:
    cells = "".join(
        f'<th class="num">{h}</th>' if i in numeric else f"<th>{h}</th>"
        for i, h in enumerate(heads)
    )
    body = rows or f"<tr><td colspan={len(heads)}>{html.escape(empty)}</td></tr>"
    return f"<table><thead><tr>{cells}</tr></thead><tbody>{body}</tbody></table>"
