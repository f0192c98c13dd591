"""What was done in a recorded session, and how the robot answered each: the report's rows.

Each thing someone did (the person, on the simulated vest the scenario's events, on a
robot what its sensors and recognizer saw; the therapist's presses; an operator's
commands) is paired with the robot's answer: the actions of the first tree that acted on
it after it and before the same one did something else. Each time the person spoke while
the robot was speaking, and so was not listened to, is a row of its own.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from dataclasses import dataclass

from engine.blackboard.catalogue import (
    FORCE_LEFT_N,
    FORCE_RIGHT_N,
    GESTURE_LAST,
    HAND_SHOWN,
    IOT_INBOX,
    SPEECH_HEARD,
    TOUCH_ANY,
)
from engine.buttons.button_file import BUTTONS_TREE
from engine.recording.replay import RecordedAction, Recording
from engine.recording.told import told_events
from engine.session.events import (
    BehaviorsPaused,
    ButtonPressed,
    NotListened,
    NotUnderstood,
    SpokenOver,
    TurnTaken,
)

KINDS_IN_WORDS = {
    "touch": "touches",
    "squeeze": "squeezes and hugs",
    "hear": "words",
    "gesture": "gestures",
    "show_hand": "hands shown",
    "obstacle": "coming near",
    "press": "button presses",
    "cloud": "operator's commands",
}
"""Each kind of thing done (as a scenario names it), as the report counts it."""
ANSWER_WITHIN_S = 10.0
"""An action this soon after what the person did counts as the robot's answer."""
PRESSED_N = 1.0
"""Force on a side pad above which the person is pressing it."""


@dataclass(frozen=True)
class Moment:
    """Something someone did (``who``: the person, the therapist, the operator), and the
    robot's answer: the first actions of each tree that acted after it (the first to act
    first) before the same one did something else (none: no answer). ``not_understood``
    is what the robot heard and had no rule for; ``not_listened`` says the robot could
    not listen (it was speaking); ``stopped_saying``: the person spoke over the robot,
    which stopped saying it (after ``stopped_after_s``)."""

    at_s: float
    did: str
    answers: tuple[RecordedAction, ...]
    who: str = "the person"
    not_understood: str | None = None
    not_listened: bool = False
    gave_way: str | None = None
    """Why nothing answered: a behaviour gave way to another (one voice at a time)."""
    control: str | None = None
    """What a control button did (paused the behaviours...): no answer is awaited."""
    kind: str = ""
    """The kind of thing done, as a scenario names it (touch, squeeze, hear, press...)."""
    stopped_saying: str | None = None
    stopped_after_s: float | None = None
    counted_by: str | None = None
    """A tree that counts (twice within, held for) counted this toward its answer to the
    next one: no answer was due."""

    @property
    def of_its_own(self) -> bool:
        """A line that tells how the robot listened, with no answer awaited."""
        return self.not_listened or self.stopped_saying is not None

    @property
    def answer(self) -> RecordedAction | None:
        return self.answers[0] if self.answers else None

    @property
    def response_s(self) -> float | None:
        return None if self.answer is None else self.answer.at_s - self.at_s

    @property
    def by_tree(self) -> dict[str, tuple[RecordedAction, ...]]:
        """The answers by the tree that gave them, the first to act first."""
        found: dict[str, tuple[RecordedAction, ...]] = {}
        for action in self.answers:
            found[action.tree] = (*found.get(action.tree, ()), action)
        return found

    @property
    def is_control(self) -> bool:
        """A press of pause, resume or stop: what it did is its row's answer."""
        return self.control in CONTROLS_DID.values()


PERSON_EVENTS = ("touch", "squeeze", "gesture", "hear", "show_hand", "obstacle")
"""Scenario events that are the person doing something (not a device failing)."""


def person_moments(recording: Recording) -> list[Moment]:
    """What the person, the therapist and the operator did, in order, each with the
    robot's first answer: a simulated session's scenario events (so an answer's time
    counts from the act itself), else what the sensors and the recognizer saw; the
    therapist's presses; each time the robot could not listen."""
    told = told_events(recording)
    done: list[tuple[float, str, str, str]] = [
        (at, "the person", _did(kind, description), kind)
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
    paused = {event.t_s: event.paused for event in told if isinstance(event, BehaviorsPaused)}
    controls: dict[float, str] = {}
    for event in told:
        if isinstance(event, ButtonPressed):
            who = "the scenario" if event.by == "scenario" else "the therapist"
            done.append((event.t_s, who, f"pressed the button \u201c{event.label}\u201d", "press"))
            control = _control_done(event, paused.get(event.t_s))
            if control:
                controls[event.t_s] = control
    done += [
        (event.from_s, "the person", "spoke while the robot was speaking", "not_listened")
        for event in told
        if isinstance(event, NotListened)
    ]
    spoken_over = {event.from_s: event for event in told if isinstance(event, SpokenOver)}
    done += [(at, "the person", "spoke over the robot", "spoken_over") for at in spoken_over]
    misunderstood = [event for event in told if isinstance(event, NotUnderstood)]
    yielded = [e for e in told if isinstance(e, TurnTaken) and e.turn in ("yields", "waits")]
    actions = recording.actions()
    reporting = {a.tree for a in actions if a.action == "report"}
    ordered = sorted(done, key=lambda item: item[0])
    moments = []
    for index, (at, who, did, kind) in enumerate(ordered):
        if kind == "not_listened":  # a line of its own: nothing to answer
            moments.append(Moment(at, did, (), who, not_listened=True, kind=kind))
            continue
        if kind == "spoken_over":  # the robot's answer: it stopped talking
            event = spoken_over[at]
            stopped = Moment(at, did, (), who, kind=kind, stopped_saying=event.saying)
            moments.append(dataclasses.replace(stopped, stopped_after_s=event.t_s - at))
            continue
        if kind == "press" and at in controls:  # what it did is its answer
            moments.append(Moment(at, did, (), who, control=controls[at], kind=kind))
            continue
        later = [  # the next thing the same one did ends the wait for an answer
            t
            for t, w, _, k in ordered[index + 1 :]
            if t > at and w == who and k not in ("not_listened", "spoken_over")
        ]
        until = min([at + ANSWER_WITHIN_S, *later])
        window = [  # a command's report is bookkeeping for the cloud, not an answer
            a
            for a in actions
            if at <= a.at_s < until and a.action != "report" and _answers(kind, a.tree, reporting)
        ]
        answers = _each_tree_s_first(window)
        heard = next(
            (e.text for e in misunderstood if at <= e.t_s < until and kind == "hear"), None
        )
        paused_then = [p for t, p in sorted(paused.items()) if t <= at]
        gave_way = "the behaviours were paused" if paused_then and paused_then[-1] else None
        gave_way = gave_way or next(
            (
                f"{e.tree} gave way to {e.other}, who had the {e.resource}"
                for e in yielded
                if at <= e.t_s < until and _answers(kind, e.tree, reporting)
            ),
            None,
        )
        moments.append(Moment(at, did, answers, who, heard, gave_way=gave_way, kind=kind))
    return _counted(moments, _counting_trees(recording))


COUNTING_NODES = ("TimesWithin", "HeldFor")
"""Nodes whose tree answers only the second (or a held) thing done: the first is counted."""


def _counting_trees(recording: Recording) -> set[str]:
    return {
        tree.name
        for tree in recording.trees
        if any(node.type in COUNTING_NODES for node in tree.nodes)
    }


def _counted(moments: list[Moment], counting: set[str]) -> list[Moment]:
    """Each unanswered moment that a counting tree counted toward its answer to the next
    one of the same kind (the first of "squeezed twice"), marked so: the robot did what it
    was made to do, it did not fail to answer."""
    marked = list(moments)
    for index, moment in enumerate(moments):
        if moment.answer is not None or moment.of_its_own or moment.is_control:
            continue
        later = next(
            (m for m in moments[index + 1 :] if m.who == moment.who and m.kind == moment.kind),
            None,
        )
        if later is None or later.at_s - moment.at_s > ANSWER_WITHIN_S:
            continue
        tree = next((a.tree for a in later.answers if a.tree in counting), None)
        if tree is not None:
            marked[index] = dataclasses.replace(moment, counted_by=tree)
    return marked


ANSWERING_TREES = 3
"""Trees whose answers a row shows (one answers at once, another after a hold...)."""


def _each_tree_s_first(window: list[RecordedAction]) -> tuple[RecordedAction, ...]:
    """The first few actions of each tree that acted in ``window``, the first to act first:
    an answer at once and one that comes later (a hug held for 3 s) both show."""
    trees: list[str] = []
    for action in window:
        if action.tree not in trees:
            trees.append(action.tree)
    chosen = trees[:ANSWERING_TREES]
    return tuple(
        action
        for tree in chosen
        for action in [a for a in window if a.tree == tree][:ANSWERING_TREES]
    )


CONTROLS_DID = {
    "pause": "paused the behaviours",
    "resume": "resumed the behaviours",
    "stop": "stopped everything and paused the behaviours",
}


def _control_done(press: ButtonPressed, paused: bool | None) -> str | None:
    """What a control button's press did (a recording before presses kept their control:
    the pause or resume that came with it), or None for a button that acts."""
    if not press.done:
        return "nothing: the button was not shown then"
    if press.control:
        return CONTROLS_DID.get(press.control)
    if paused is not None:
        return CONTROLS_DID["pause" if paused else "resume"]
    return None


def _did(kind: str, description: str) -> str:
    """A scenario event's description as what the person did (a verb first)."""
    if kind == "touch":
        pad, _, rest = description.partition(" touched")
        return f"touched {pad}{rest}"
    if kind == "gesture":
        return "made a gesture: " + description.removeprefix("gesture ")
    if kind == "obstacle":
        return "came near: " + description.removeprefix("obstacle at ")
    if kind == "show_hand":
        return "held up " + description
    return description.removeprefix("someone ")


def _answers(kind: str, tree: str, reporting: set[str]) -> bool:
    """Whether ``tree`` can answer something done (``kind``, as a scenario names it): a
    press is answered by the buttons, an operator's command by the trees that report
    commands (``reporting``), the person by the other trees."""
    if kind == "press":
        return tree == BUTTONS_TREE
    if kind == "cloud":
        return tree in reporting
    return tree != BUTTONS_TREE and tree not in reporting


def sensed(recording: Recording) -> list[tuple[float, str, str, str]]:
    """What the person (and the operator) did as the robot sensed it (on a robot in a real
    room): (moment, who, what, the kind of scenario event it would be)."""
    done: list[tuple[float, str, str]] = []
    was_touched = False
    for at, touched in recording.key_history(TOUCH_ANY):
        if touched and not was_touched:
            done.append((at, "touched the vest", "touch"))
        was_touched = bool(touched)
    left = dict(recording.key_history(FORCE_LEFT_N))
    right = dict(recording.key_history(FORCE_RIGHT_N))
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
    for at, gesture in recording.key_history(GESTURE_LAST):
        done.append((at, f"made a gesture: {gesture}", "gesture"))
    for at, text in recording.key_history(SPEECH_HEARD):
        done.append((at, f"said \u201c{text}\u201d", "hear"))
    for at, fingers in recording.key_history(HAND_SHOWN):
        done.append((at, f"showed {fingers} finger{'' if fingers == 1 else 's'}", "show_hand"))
    found = [(at, "the person", what, kind) for at, what, kind in done]
    for at, command in recording.key_history(IOT_INBOX):
        kind = command.get("type", "?") if isinstance(command, dict) else command
        found.append((at, "the operator", f"sent {kind}", "cloud"))
    return found


def not_understood(recording: Recording) -> list[NotUnderstood]:
    """Each utterance no dialog rule matched, once each, with what the robot did instead
    (asked whether it heard a rule, or said a reprompt); a format 1 recording's are read
    from the dialog node's feedback (the tree and why left blank)."""
    if recording.format >= 2:
        return [event for event in told_events(recording) if isinstance(event, NotUnderstood)]
    found: list[NotUnderstood] = []
    last: tuple[float, str] | None = None
    for at, feedback in recording.feedback_containing("no rule matches "):
        if last is not None and last[1] == feedback and at - last[0] <= ANSWER_WITHIN_S:
            continue  # the same node's next status (RUNNING, then done) says it again
        last = (at, feedback)
        heard = feedback.split("no rule matches ", 1)[1].split(": ", 1)[0]
        found.append(NotUnderstood(at, "", heard, ""))
    return found


def done_by_kind(moments: list[Moment]) -> list[tuple[str, str, int]]:
    """How many times each did each kind of thing (who, the kind in words, times): the
    person's first, so the therapist's presses are never read as the person's activity;
    the most done first."""
    kinds = Counter(
        (m.who, KINDS_IN_WORDS.get(m.kind, "other")) for m in moments if not m.of_its_own
    )
    rows = [(who, kind, count) for (who, kind), count in kinds.items()]
    return sorted(rows, key=lambda row: (row[0] != "the person", row[0], -row[2]))


def outages(recording: Recording) -> list[tuple[str, float, float | None]]:
    """(device, offline at, back at or None) for each time a device dropped out."""
    found: list[tuple[str, float, float | None]] = []
    for key in recording.keys_like("/devices/%/ok"):
        device = key.removeprefix("/devices/").removesuffix("/ok")
        since: float | None = None
        for at, ok in recording.key_history(key):
            if ok is False and since is None:
                since = at
            elif ok is True and since is not None:
                found.append((device, since, at))
                since = None
        if since is not None:  # to the end (from the start: never there, or no model)
            found.append((device, since, None))
    return sorted(found, key=lambda item: item[1])
