"""A recorded session as a therapist reads it (``vest report FILE``): one static HTML page.

Who, when and with which profile; what the person did (touched, hugged, waved, said,
showed fingers), what the therapist did (the buttons pressed) and how the robot answered,
with how long it took, one line each (a sentence it did not understand is answered as
such; a time it could not listen because it was speaking is a line of its own); how often
each behaviour acted; what the robot did not understand; what the safety envelope refused,
slowed or stopped, with its rule and the sensors it read; devices that dropped out; and the
sensors over the session, drawn as inline SVG. Everything comes from the recording's
account of the session (:mod:`engine.recording.told`), its blackboard and actions, so a
session on the robot reads the same as one on the simulated vest. Printable on A4.
"""

from __future__ import annotations

import datetime
import html
import json
from collections import Counter

import yaml

from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    RANGE_CENTER_MM,
    TOUCH_ANY,
)
from engine.recording.moments import (
    Moment,
    done_by_kind,
    not_understood,
    outages,
    person_moments,
)
from engine.recording.replay import RecordedAction, Recording
from engine.recording.report_page import REPORT_HEAD, STYLE, note_section, printable, table
from engine.recording.report_plots import numbers, plot
from engine.recording.told import told_events
from engine.session.events import NotUnderstood, SafetyAction


def _lasted(since: float, back: float | None) -> str:
    if back is None:
        return "the whole session" if since < 0.5 else "until the end"
    return f"{back - since:.1f} s"


def _answer_text(action: RecordedAction) -> str:
    """An action as the robot's answer: what it did, or tried and could not do, or began
    and did not finish."""
    if action.outcome == "failed":
        return f"could not {_action_text(action, tried=True)} ({action.why})"
    cut = " (cut short)" if action.cut else ""
    return _action_text(action) + cut


def _action_text(action: RecordedAction, *, tried: bool = False) -> str:
    """What an action did (``tried``: what it would have done), in words."""
    args = action.args
    verbs = (
        ("say", "light its face", "turn its", "read its")
        if tried
        else ("said", "lit its face", "turned its", "read its")
    )
    if action.action == "say":
        return f"{verbs[0]} \u201c{args.get('text', '')}\u201d"
    if action.action == "led" and args.get("color") == "off":
        return "turn its face lights off" if tried else "turned its face lights off"
    if action.action == "led":
        return f"{verbs[1]} {args.get('color', '')}"
    if action.action == "servo":
        return f"{verbs[2]} {args.get('joint', '')} to {args.get('angle_deg', ''):g} deg"
    if action.action == "read":
        return f"{verbs[3]} {args.get('sensor', '')} sensor"
    return f"{action.action} {json.dumps(args)}"


def _times(count: int) -> str:
    return f"{count} time{'s' if count != 1 else ''}"


def _answer_cell(moment: Moment) -> tuple[str, str]:
    """The robot's answer to ``moment`` as the report shows it (HTML), and its delay."""
    if moment.not_listened:
        return '<span class="none">could not listen: it was speaking</span>', "-"
    if moment.stopped_saying is not None:
        said = html.escape(moment.stopped_saying)
        return (
            f"stopped talking (it was saying \u201c{said}\u201d)",
            f"{moment.stopped_after_s:.2f} s",
        )
    if moment.control is not None:
        return html.escape(moment.control), "-"
    if moment.counted_by is not None:
        return f"counted by {html.escape(moment.counted_by)}, which answers the next one", "-"
    if moment.answer is None and moment.not_understood is None:
        why = f": {moment.gave_way}" if moment.gave_way else ""
        return f'<span class="none">no answer{html.escape(why)}</span>', "-"
    parts = []
    if moment.not_understood is not None:
        parts.append(f"did not understand \u201c{moment.not_understood}\u201d")
    for tree, actions in moment.by_tree.items():
        done = ", ".join(_answer_text(action) for action in actions)
        later = actions[0].at_s - moment.at_s
        after = f" ({later:.2f} s after)" if actions[0] is not moment.answer else ""
        parts.append(f"{tree}: {done}{after}")
    took = f"{moment.response_s:.2f} s" if moment.response_s is not None else "-"
    return html.escape("; ".join(parts)), took


def _instead(miss: NotUnderstood) -> str:
    """What the robot did when it did not understand."""
    if miss.asked:
        return f"asked whether it heard \u201c{miss.asked}\u201d"
    if miss.reprompt:
        return f"said it in other words (reprompt {miss.reprompt})"
    return "said its fallback" if miss.tree else ""


SAFETY_DID = {
    "refused": "refused a move",
    "slowed": "slowed a move",
    "stopped": "stopped a move",
    "held": "kept an arm from going back to rest until it could",
}


def _safety_rows(recording: Recording) -> str:
    """Each move the envelope refused, slowed or stopped, as table rows (HTML)."""
    return "".join(
        f"<tr><td class='num'>{event.t_s:.1f} s</td>"
        f"<td>{html.escape(SAFETY_DID.get(event.action, event.action))}</td>"
        f"<td>{html.escape(event.joint)}</td><td>{html.escape(event.rule)}</td>"
        f"<td>{html.escape(', '.join(event.devices) or '-')}</td>"
        f"<td>{html.escape(event.why)}</td></tr>"
        for event in told_events(recording)
        if isinstance(event, SafetyAction)
    )


def _started(epoch: str | None) -> str:
    """When the session was recorded, as a date a person reads (UTC)."""
    try:
        stamp = datetime.datetime.fromtimestamp(float(epoch or ""), tz=datetime.UTC)
    except (ValueError, OverflowError, OSError):
        return "date unknown"
    return stamp.strftime("%d %B %Y, %H:%M UTC")


LEFT_OUT_MEANS = {
    "sensor readings": "touches, squeezes, distances, gestures, temperatures and what the "
    "camera counted are not in this report, nor the sensors' charts",
    "speech as text": "what the person said is not in this report: only that they spoke",
}
"""What a therapist must know is missing from a report, by what consent left out."""


def _left_out(meta: dict[str, str]) -> str:
    """A paragraph saying what the person's consent kept out of the recording ('' when
    nothing that a report shows was left out)."""
    left = [part.strip() for part in meta.get("left_out", "").split(",") if part.strip()]
    missing = [LEFT_OUT_MEANS[part] for part in left if part in LEFT_OUT_MEANS]
    if not missing:
        return ""
    said = "; ".join(missing)
    return (
        f'<p class="warning">Consent: not kept of this person: {html.escape(", ".join(left))}. '
        f"So {html.escape(said)}. What is missing did still happen.</p>"
    )


SCENARIO_OF_NONE = ("", "(the buttons alone)")
"""A session's ``scenario`` fact when no scenario was played (a real session)."""


def simulated(meta: dict[str, str]) -> bool:
    """Whether a recording is of no child: on the simulated vest (a practice, what the
    person did acted on the buttons page), on a virtual clock (``--fast``), or with a
    scenario playing the person (recordings before the clock and the vest were kept)."""
    if meta.get("vest") == "simulated":
        return True
    if "clock" in meta:
        return meta["clock"] == "virtual" or meta.get("scenario", "") not in SCENARIO_OF_NONE
    return meta.get("scenario", "") not in SCENARIO_OF_NONE


def report_html(recording: Recording, note: str = "") -> str:
    """The report as one HTML document (no outside files), with the therapist's ``note``
    (plain text; a blank line between paragraphs) when there is one."""
    end = recording.duration_s
    moments = person_moments(recording)
    answered = [  # an answer the robot could not give (refused, failed) is no answer
        m.response_s
        for m in moments
        if m.response_s is not None and any(a.outcome != "failed" for a in m.answers)
    ]
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
    fired.update(action.tree for action in recording.actions() if action.outcome != "failed")
    answering = Counter(tree for moment in moments for tree in moment.by_tree)
    described = descriptions(recording)
    behaviours = "".join(
        f"<tr><td>{html.escape(tree)}</td><td>{html.escape(described.get(tree, ''))}</td>"
        f"<td class='num'>{answering[tree]}</td><td class='num'>{count}</td></tr>"
        for tree, count in sorted(fired.items(), key=lambda item: (-answering[item[0]], -item[1]))
    )
    by_kind = "".join(
        f"<tr><td>{html.escape(who)}</td><td>{html.escape(kind)}</td>"
        f"<td class='num'>{count}</td><td class='num'>{count / (end / 60):.1f}</td></tr>"
        for who, kind, count in done_by_kind(moments)
        if end > 0
    )
    misses = not_understood(recording)
    missed = "".join(
        f"<tr><td class='num'>{miss.t_s:.1f} s</td><td>{html.escape(miss.text)}</td>"
        f"<td>{html.escape(_instead(miss))}</td></tr>"
        for miss in misses
    )
    asked = sum(1 for miss in misses if miss.asked)
    reprompted = sum(1 for miss in misses if miss.reprompt)
    dropped = "".join(
        f"<tr><td>{html.escape(device)}</td><td class='num'>{since:.1f} s</td>"
        f"<td class='num'>{'-' if back is None else f'{back:.1f} s'}</td>"
        f"<td class='num'>{_lasted(since, back)}</td></tr>"
        for device, since, back in outages(recording)
    )
    median = sorted(answered)[len(answered) // 2] if answered else None
    acts = [m for m in moments if not m.of_its_own and not m.is_control]
    controls = sum(1 for m in moments if m.is_control)
    unheard = sum(1 for m in moments if m.not_listened)
    spoken_over = sum(1 for m in moments if m.stopped_saying is not None)
    summary = (
        f"{len(acts)} things done (by the person, the therapist, the scenario or an "
        f"operator), each a row below; the robot answered {len(answered)}"
        + (f", typically within {median:.2f} s" if median is not None else "")
        + "."
        + (
            f" Besides, the buttons paused, resumed or stopped the behaviours {_times(controls)}"
            " (a row each)."
            if controls
            else ""
        )
        + (
            f" {_times(spoken_over).capitalize()} the person spoke over the robot, and it "
            "stopped talking to listen (a row each)."
            if spoken_over
            else ""
        )
        + (
            f" {_times(unheard).capitalize()} the person spoke while the robot was speaking, "
            "and it could not listen (a row each)."
            if unheard
            else ""
        )
        + (
            f" It did not understand {_times(len(misses))}: it asked whether it heard right "
            f"{_times(asked)} and said it in other words {_times(reprompted)}."
            if misses
            else ""
        )
    )
    if simulated(recording.meta):
        summary += (
            " A simulated session: on the simulated vest, a scenario or the buttons page "
            "played the person's part (progress reports leave it out unless asked)."
        )
    cut = recording.cut_short
    plots = [
        plot(
            "Squeeze on the side pads",
            "N",
            [
                ("left", "#c62828", numbers(recording.key_history(FORCE_LEFT_N))),
                ("right", "#1565c0", numbers(recording.key_history(FORCE_RIGHT_N))),
            ],
            end,
        ),
        plot(
            "Touched",
            "yes = 1",
            [("any pad", "#2e7d32", numbers(recording.key_history(TOUCH_ANY)))],
            end,
        ),
        plot(
            "Someone in front",
            "cm",
            [("center distance", "#6a1b9a", numbers(recording.key_history(RANGE_CENTER_MM), 0.1))],
            end,
        ),
    ]
    meta = recording.meta
    profile = f"profile {meta['profile']}" if meta.get("profile") else "no profile"
    recorded = html.escape(recording.path.name)
    robot = html.escape(meta.get("robot_config", "?"))
    person = html.escape(meta.get("person") or "no person named")
    when = html.escape(_started(meta.get("started")))
    return printable(
        "\n".join(
            [
                REPORT_HEAD,
                f"<title>Session report: {recorded}</title>",
                f"<style>{STYLE(encoding='utf-8')}</style></head><body>",
                f"<h1>Session report{' (simulated: no child)' if simulated(meta) else ''}</h1>",
                f'<p class="meta">{when} &middot; {person} &middot; {end:.1f} s &middot; '
                f"{html.escape(profile)} &middot; robot {robot} &middot; {recorded}</p>",
                f"<p>{html.escape(summary)}</p>",
                note_section(note),
                _left_out(meta),
                f'<p class="warning">{html.escape(cut)}: this report is of what it holds.</p>'
                if cut
                else "",
                "<h2>What the person did, and how the robot answered</h2>",
                table(
                    ["when", "who", "did", "the robot", "answer after"],
                    rows_html,
                    "nothing",
                    numeric={0, 4},
                ),
                "<h2>What was done, by whom and kind</h2>",
                table(
                    ["who", "kind", "times", "per minute"],
                    by_kind,
                    "nothing was done",
                    numeric={2, 3},
                ),
                "<h2>How often each behaviour answered</h2>",
                "<p>Times it answered something done (a row above), and its actions: each light, "
                "word or move it could make (not those refused or failed).</p>",
                table(
                    ["behaviour", "what it does", "times it answered", "actions"],
                    behaviours,
                    "none acted",
                    numeric={2, 3},
                ),
                "<h2>What the robot did not understand</h2>",
                table(
                    ["when", "heard", "the robot"],
                    missed,
                    "everything it heard matched a rule"
                    if any(moment.kind == "hear" for moment in moments)
                    else "nothing was said to it",
                    numeric={0},
                ),
                "<h2>What the safety envelope did</h2>",
                table(
                    ["when", "did", "joint", "rule", "sensors", "why"],
                    _safety_rows(recording),
                    "nothing: no move was refused, slowed or stopped",
                    numeric={0},
                ),
                "<h2>Devices that dropped out</h2>",
                table(
                    ["device", "offline at", "back at", "for"], dropped, "none", numeric={1, 2, 3}
                ),
                "<h2>The sensors over the session</h2>",
                *plots,
                "</body></html>\n",
            ]
        )
    )


def descriptions(recording: Recording) -> dict[str, str]:
    """Each behaviour's description, as its tree file says it (the version first run)."""
    found: dict[str, str] = {}
    for row in recording.table("trees"):
        if row["tree"] in found:
            continue
        try:
            document = yaml.safe_load(row["source"] or "")
        except yaml.YAMLError:
            continue
        described = document.get("description") if isinstance(document, dict) else None
        found[row["tree"]] = " ".join(str(described).split()) if described else ""
    return found
