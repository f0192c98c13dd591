"""A person's progress across sessions (``vest report --person kid-17``): how what they
did, how the robot answered, how fast, and what it did not understand changed from one
session to the next, overall and per behaviour. One HTML page, printable on A4.

Each session is summed up from its recording the way its own report reads it
(:func:`~engine.recording.moments.person_moments`); a session whose file is gone is
listed as such, never silently left out.
"""

from __future__ import annotations

import datetime
import html
import statistics
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

from engine.recording.moments import not_understood, person_moments
from engine.recording.replay import Recording
from engine.recording.report import simulated
from engine.recording.report_page import REPORT_HEAD, STYLE, printable
from engine.recording.report_plots import per_session_plot

THE_PERSON = "the person"


@dataclass(frozen=True)
class SessionSummary:
    """One session of a person. Counts are of what the person did (not the therapist or an
    operator); ``answer_s`` holds each answer time in seconds; ``by_behaviour`` the answer
    times of each behaviour (tree) that answered."""

    path: Path
    started: float
    length_s: float
    did: int
    answer_s: tuple[float, ...]
    not_understood: int
    not_listened: int
    by_behaviour: dict[str, tuple[float, ...]] = field(default_factory=dict)
    simulated: bool = False
    """A scripted session on the simulated vest (a scenario, or ``--fast``): no person."""
    counted: int = 0
    """Things done that a tree counted toward its answer to the next (the first of two)."""
    spoken_over: int = 0
    """Times the person spoke over the robot and it stopped to listen (``not_listened``:
    times it could not listen then)."""

    @property
    def answered(self) -> int:
        """Things done the robot answered (not those it counted toward an answer)."""
        return len(self.answer_s)

    @property
    def answered_words(self) -> str:
        """How many it answered, and how many more it counted toward an answer: "1 (+1
        counted)"."""
        return f"{self.answered} (+{self.counted} counted)" if self.counted else str(self.answered)

    @property
    def did_per_minute(self) -> float | None:
        """What the person did per minute of the session (sessions of any length compare)."""
        return self.did / (self.length_s / 60) if self.length_s > 0 else None

    @property
    def median_answer_s(self) -> float | None:
        return statistics.median(self.answer_s) if self.answer_s else None

    @property
    def day(self) -> str:
        """When it started, as a person reads it (UTC)."""
        when = datetime.datetime.fromtimestamp(self.started, datetime.UTC)
        return when.strftime("%Y-%m-%d %H:%M")


def summarize(recording: Recording, started: float) -> SessionSummary:
    """What ``recording`` (which began at ``started``, seconds since the epoch) says of
    the person."""
    moments = [m for m in person_moments(recording) if m.who == THE_PERSON]
    acts = [m for m in moments if not m.of_its_own]
    behaviours: dict[str, list[float]] = defaultdict(list)
    times: list[float] = []
    for moment in acts:
        answer, took = moment.answer, moment.response_s
        if answer is None or took is None or all(a.outcome == "failed" for a in moment.answers):
            continue
        times.append(took)
        for tree, actions in moment.by_tree.items():  # one at once, one after a hold...
            behaviours[tree].append(actions[0].at_s - moment.at_s)
    return SessionSummary(
        recording.path,
        started,
        recording.duration_s,
        len(acts),
        tuple(times),
        len(not_understood(recording)),
        sum(moment.not_listened for moment in moments),
        {tree: tuple(found) for tree, found in behaviours.items()},
        simulated(recording.meta),
        sum(moment.counted_by is not None for moment in acts),
        sum(moment.stopped_saying is not None for moment in moments),
    )


def progress_html(
    person: str, sessions: list[SessionSummary], gone: list[Path], *, left_out: int = 0
) -> str:
    """The progress page of ``person`` over ``sessions`` (oldest first); ``gone``: indexed
    sessions whose files are no longer there; ``left_out``: simulated sessions not
    counted (those counted are marked)."""
    name = html.escape(person)
    labels = [f"{n}" for n in range(1, len(sessions) + 1)]  # the table gives each one's day
    parts = [
        REPORT_HEAD,
        f"<title>Progress: {name}</title>",
        f"<style>{STYLE(encoding='utf-8')}</style></head><body>",
        f"<h1>Progress of {name}"
        + (" (simulated sessions counted)" if any(s.simulated for s in sessions) else "")
        + "</h1>",
        f'<p class="meta">{len(sessions)} session{"" if len(sessions) == 1 else "s"}'
        + (f" from {sessions[0].day} to {sessions[-1].day}" if sessions else "")
        + "</p>",
        f"<p>{html.escape(_in_words(sessions, left_out))}</p>",
        "<p class='meta'>Counted: what the person did (touches, hugs, words, gestures), not "
        "the therapist's presses or an operator's commands, which the session reports list "
        "too. Spoke over the robot: times the person spoke while the robot was talking (it "
        "stopped to listen; not heard: it could not listen then).</p>",
    ]
    if left_out:
        parts.append(
            f"<p class='meta'>{left_out} simulated session{'s' if left_out != 1 else ''} "
            "(on the simulated vest: no child) left out: vest report --person "
            f"{name} --with-simulated counts {'them' if left_out != 1 else 'it'}, marked.</p>"
        )
    if gone:
        listed = ", ".join(html.escape(str(path)) for path in gone)
        parts.append(f'<p class="warning">Not there any more, so not counted: {listed}.</p>')
    parts += [
        "<h2>Session by session</h2>",
        _sessions_table(sessions),
        per_session_plot(
            "What the person did and what the robot answered",
            "times",
            [
                ("did per minute", "#ef6c00", [s.did_per_minute for s in sessions]),
                ("did", "#2e7d32", [float(s.did) for s in sessions]),
                ("answered", "#1565c0", [float(s.answered) for s in sessions]),
                ("not understood", "#c62828", [float(s.not_understood) for s in sessions]),
            ],
            labels,
        ),
        per_session_plot(
            "Typical time to the robot's answer",
            "s",
            [("median", "#6a1b9a", [s.median_answer_s for s in sessions])],
            labels,
        ),
        "<h2>Per behaviour: how often it answered (typical answer time)</h2>",
        _behaviours_table(sessions),
        "</body></html>\n",
    ]
    return printable("\n".join(parts))


def _in_words(sessions: list[SessionSummary], left_out: int = 0) -> str:
    if not sessions and left_out:
        return (
            "No real session of this person yet: only simulated ones, where a scenario "
            "or the buttons page played the person's part (see below)."
        )
    if not sessions:
        return "No session of this person is held."
    first, last = sessions[0], sessions[-1]
    if len(sessions) == 1:
        took = (
            f" Typical answer time: {first.median_answer_s:.2f} s."
            if first.median_answer_s is not None
            else ""
        )
        counted = (
            f", and counted {first.counted} toward an answer to the next (the first of "
            "\u201ctwice\u201d)"
            if first.counted
            else ""
        )
        return (
            f"In this session the person did {first.did} things and the robot answered "
            f"{first.answered}{counted}.{took} Not understood: {first.not_understood}."
        )
    words = (
        f"In the first session the person did {first.did} things and the robot answered "
        f"{first.answered}; in the latest, {last.did} and {last.answered}."
    )
    rates = [f"{s.did_per_minute:.1f}" for s in sessions if s.did_per_minute is not None]
    if len(rates) > 1:
        words += f" Things done per minute, session by session: {', '.join(rates)}."
    if first.median_answer_s is not None and last.median_answer_s is not None:
        words += (
            f" Typical answer time: {first.median_answer_s:.2f} s, then "
            f"{last.median_answer_s:.2f} s."
        )
    words += (
        f" Not understood: {first.not_understood}, then {last.not_understood}."
        if len(sessions) > 1
        else f" Not understood: {first.not_understood}."
    )
    return words


def _spoke_over(session: SessionSummary) -> str:
    unheard = session.not_listened
    total = session.spoken_over + unheard
    return f"{total} ({unheard} not heard)" if unheard else str(total)


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f} s"


def _sessions_table(sessions: list[SessionSummary]) -> str:
    heads = ["#", "day", "length", "did", "per minute", "answered", "typical answer"]
    heads += ["not understood", "spoke over the robot"]
    rows = "".join(
        f"<tr><td class='num'>{n}</td><td>{s.day}{' (simulated)' if s.simulated else ''}</td>"
        f"<td class='num'>{s.length_s:.0f} s</td><td class='num'>{s.did}</td>"
        f"<td class='num'>{'-' if s.did_per_minute is None else f'{s.did_per_minute:.1f}'}</td>"
        f"<td class='num'>{s.answered_words}</td>"
        f"<td class='num'>{_seconds(s.median_answer_s)}</td>"
        f"<td class='num'>{s.not_understood}</td><td class='num'>{_spoke_over(s)}</td></tr>"
        for n, s in enumerate(sessions, 1)
    )
    head = "".join(f"<th>{h}</th>" for h in heads)
    body = rows or f"<tr><td colspan={len(heads)}>no sessions</td></tr>"
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _behaviours_table(sessions: list[SessionSummary]) -> str:
    trees = sorted({tree for s in sessions for tree in s.by_behaviour})
    head = "<th>behaviour</th>" + "".join(
        f"<th class='num'>{n}</th>" for n in range(1, len(sessions) + 1)
    )
    rows = []
    for tree in trees:
        cells = []
        for s in sessions:
            times = s.by_behaviour.get(tree, ())
            typical = f" ({statistics.median(times):.2f} s)" if times else ""
            cells.append(f"<td class='num'>{len(times)}{typical}</td>")
        rows.append(f"<tr><td>{html.escape(tree)}</td>{''.join(cells)}</tr>")
    body = "".join(rows) or f"<tr><td colspan={len(sessions) + 1}>no behaviour answered</td></tr>"
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
