"""A recorded session as a therapist reads it (``vest report FILE``): one static HTML page.

What the person did (touched, hugged, waved, said, showed fingers) and how the robot
answered, with how long it took; how often each behaviour acted; what the robot did not
understand; devices that dropped out; and the sensors over the session, drawn as inline
SVG. Everything comes from the recording's blackboard and actions, so a session on the
robot reads the same as one on the simulated vest. Printable on A4.
"""

from __future__ import annotations

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
from engine.recording.replay import RecordedAction, Recording

ANSWER_WITHIN_S = 10.0
"""An action this soon after what the person did counts as the robot's answer."""
PRESSED_N = 1.0
"""Force on a side pad above which the person is pressing it."""


@dataclass(frozen=True)
class Moment:
    """Something the person did, and the robot's answer: the actions of the first tree
    that acted after it and before the person's next act (none: no answer)."""

    at_s: float
    did: str
    answers: tuple[RecordedAction, ...]

    @property
    def answer(self) -> RecordedAction | None:
        return self.answers[0] if self.answers else None

    @property
    def response_s(self) -> float | None:
        return None if self.answer is None else self.answer.at_s - self.at_s


def _rows(recording: Recording, key: str) -> list[tuple[float, Any]]:
    return recording.key_history(key)


PERSON_EVENTS = ("touch", "squeeze", "gesture", "hear", "show_hand", "obstacle", "cloud")
"""Scenario events that are someone doing something (not a device failing)."""


def person_moments(recording: Recording) -> list[Moment]:
    """What the person did, in order, each with the robot's first answer: a simulated
    session's scenario events (so an answer's time counts from the act itself), else
    what the sensors and the recognizer saw."""
    done = [
        (at, description) for at, kind, description in recording.world() if kind in PERSON_EVENTS
    ] or sensed(recording)
    actions = recording.actions()
    ordered = sorted(done)
    moments = []
    for index, (at, did) in enumerate(ordered):
        later = [t for t, _ in ordered[index + 1 :] if t > at]
        until = min([at + ANSWER_WITHIN_S, *later[:1]])
        window = [a for a in actions if at <= a.at_s < until]
        tree = window[0].tree if window else None
        answers = tuple(a for a in window if a.tree == tree)[:3]
        moments.append(Moment(at, did, answers))
    return moments


def sensed(recording: Recording) -> list[tuple[float, str]]:
    """What the person did as the robot sensed it (on a robot in a real room)."""
    done: list[tuple[float, str]] = []
    was_touched = False
    for at, touched in _rows(recording, TOUCH_ANY):
        if touched and not was_touched:
            done.append((at, "touched the vest"))
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
            done.append((at, f"{what} ({level['left']:.1f} N left, {level['right']:.1f} N right)"))
        pressing = now
    for at, gesture in _rows(recording, GESTURE_LAST):
        done.append((at, f"made a gesture: {gesture}"))
    for at, text in _rows(recording, SPEECH_HEARD):
        done.append((at, f"said \u201c{text}\u201d"))
    for at, fingers in _rows(recording, HAND_SHOWN):
        done.append((at, f"showed {fingers} finger{'' if fingers == 1 else 's'}"))
    for at, command in _rows(recording, IOT_INBOX):
        kind = command.get("type", "?") if isinstance(command, dict) else command
        done.append((at, f"(the operator sent {kind})"))
    return done


def not_understood(recording: Recording) -> list[tuple[float, str]]:
    """(moment, what the robot was told) for each utterance no dialog rule matched."""
    return [
        (at, feedback.split("no rule matches ", 1)[1].split(": ", 1)[0])
        for at, feedback in recording.feedback_containing("no rule matches ")
    ]


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


def _plot(
    title: str,
    unit: str,
    series: list[tuple[str, str, list[tuple[float, float | None]]]],
    end_s: float,
) -> str:
    """A small line plot (SVG) of step-wise series over the session."""
    width, height, left, bottom = 680, 150, 48, 22
    values = [v for _, _, points in series for _, v in points if v is not None]
    if not values:
        return ""
    top = max(values) if max(values) > 0 else 1.0

    def x(t: float) -> float:
        return left + (width - left - 24) * (t / end_s if end_s else 0.0)

    def y(v: float) -> float:
        return 8 + (height - bottom - 8) * (1 - v / (top * 1.1))

    def text(at_x: float, at_y: float, words: str, anchor: str = "end", fill: str = "") -> str:
        colour = f' style="fill: {fill}"' if fill else ""
        return (
            f'<text x="{at_x:.1f}" y="{at_y:.1f}" class="tick" text-anchor="{anchor}"{colour}>'
            f"{html.escape(words)}</text>"
        )

    base = height - bottom
    parts = [
        f'<svg viewBox="0 0 {width} {height}" role="img" aria-label="{html.escape(title)}">',
        f'<text x="{left}" y="12" class="plot-title">{html.escape(title)} ({unit})</text>',
        f'<line x1="{left}" y1="{base}" x2="{width - 8}" y2="{base}" class="axis"/>',
        text(left - 4, y(top) + 4, f"{top:.3g}"),
        text(left - 4, base + 4, "0"),
    ]
    step = max(1.0, round(end_s / 8))
    t = 0.0
    while t <= end_s + 1e-9:
        parts.append(text(x(t), height - 6, f"{t:g} s", "middle"))
        t += step
    for index, (name, colour, points) in enumerate(series):
        dash = ' stroke-dasharray="5 3"' if index else ""
        for run in _runs(points, end_s):  # no reading (nothing in range): no line
            joined = " ".join(f"{x(at):.1f},{y(value):.1f}" for at, value in run)
            parts.append(f'<polyline fill="none" stroke="{colour}"{dash} points="{joined}"/>')
        parts.append(text(width - 10, 20 + 12 * index, name, "end", colour))
    parts.append("</svg>")
    return "".join(parts)


def _runs(
    points: list[tuple[float, float | None]], end_s: float
) -> list[list[tuple[float, float]]]:
    """Step-wise line pieces between the moments a value was absent."""
    runs: list[list[tuple[float, float]]] = []
    current: list[tuple[float, float]] = []
    for index, (at, value) in enumerate(points):
        until = points[index + 1][0] if index + 1 < len(points) else end_s
        if value is None:
            if current:
                runs.append(current)
            current = []
            continue
        current += [(at, value), (until, value)]
    if current:
        runs.append(current)
    return runs


def _numbers(rows: list[tuple[float, Any]], scale: float = 1.0) -> list[tuple[float, float | None]]:
    """Readings as numbers (True is 1); None where the sensor saw nothing."""
    return [(at, float(v) * scale if isinstance(v, int | float) else None) for at, v in rows]


STYLE = (Path(__file__).resolve().parent / "report.css").read_text
"""The report's style sheet, read when a report is written (it goes inside the page)."""


def report_html(recording: Recording) -> str:
    """The report as one HTML document (no outside files)."""
    end = recording.duration_s
    moments = person_moments(recording)
    answered = [m.response_s for m in moments if m.response_s is not None]
    rows = []
    for moment in moments:
        if moment.answer is None:
            answer, took = '<span class="none">no answer</span>', "-"
        else:
            done = ", ".join(_answer_text(action) for action in moment.answers)
            answer = html.escape(f"{moment.answer.tree}: {done}")
            took = f"{moment.response_s:.2f} s"
        rows.append(
            f"<tr><td class='num'>{moment.at_s:.1f} s</td><td>{html.escape(moment.did)}</td>"
            f"<td>{answer}</td><td class='num'>{took}</td></tr>"
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
    summary = (
        f"{len(moments)} things the person did; the robot answered {len(answered)}"
        + (f", typically within {median:.2f} s" if median is not None else "")
        + "."
    )
    plots = [
        _plot(
            "Squeeze on the side pads",
            "N",
            [
                ("left", "#c62828", _numbers(_rows(recording, FORCE_LEFT_N))),
                ("right", "#1565c0", _numbers(_rows(recording, FORCE_RIGHT_N))),
            ],
            end,
        ),
        _plot(
            "Touched",
            "yes = 1",
            [("any pad", "#2e7d32", _numbers(_rows(recording, TOUCH_ANY)))],
            end,
        ),
        _plot(
            "Someone in front",
            "cm",
            [("center distance", "#6a1b9a", _numbers(_rows(recording, RANGE_CENTER_MM), 0.1))],
            end,
        ),
    ]
    meta = recording.meta
    profile = meta.get("profile") or "no profile"
    recorded = html.escape(recording.path.name)
    robot = html.escape(meta.get("robot_config", "?"))
    return "\n".join(
        [
            '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">',
            f"<title>Session report: {recorded}</title>",
            f"<style>{STYLE(encoding='utf-8')}</style></head><body>",
            "<h1>Session report</h1>",
            f'<p class="meta">{recorded} &middot; {end:.1f} s &middot; '
            f"{html.escape(profile)} &middot; robot {robot}</p>",
            f"<p>{html.escape(summary)}</p>",
            "<h2>What the person did, and how the robot answered</h2>",
            _table(
                ["when", "the person", "the robot", "answer after"],
                rows_html,
                "nothing",
                numeric={0, 3},
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
