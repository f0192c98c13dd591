"""What happened in a session, as typed events: the one account every reader shares.

BehaviorTree.CPP gives all its loggers one base (``StatusChangeLogger``): the console,
file, SQLite and Groot2 loggers read the same status changes. vest does the same for the
whole session: producers (the scheduler, the action log, the turns, the safety envelope,
the buttons, the blackboard, hot reload, the scenario) publish these events on the
:class:`~engine.session.stream.SessionStream`, and the readers (the terminal timeline,
``--json``, the recorder, the live view, the cloud's telemetry) each turn them into what
they show or keep. Nobody keeps a second account of what happened.

Every event is immutable and carries ``t_s``, the clock time it happened (seconds; a
node's status holds from its tick's deadline). Its ``kind`` names it on the wire and in
recordings. An event whose free text may hold what a person said or what a sensor read
says so in ``carries`` (:data:`~engine.blackboard.catalogue.Carries`): the consent gate
(:mod:`engine.privacy.consent_gate`) reads it and never travels further.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

from engine.blackboard.catalogue import NOTHING, Carries


@dataclass(frozen=True, slots=True)
class NodeInfo:
    """One node of a tree version: its number (depth-first, as ``vest render`` numbers
    them; ``n0`` is the root), path, type, label (its type and parameters), depth, and
    what it does in plain words, as drawn ("" when not known: recordings before format 4
    kept none)."""

    index: int
    path: str
    type: str
    label: str
    depth: int
    words: str = ""


@dataclass(frozen=True, slots=True)
class TreeStarted:
    """A version of a tree began running: at the start, and after each hot reload."""

    kind: ClassVar[str] = "tree"
    t_s: float
    tree: str
    version: int
    file: Path
    files: tuple[Path, ...]
    rate_hz: float
    priority: int
    nodes: tuple[NodeInfo, ...]
    dot: str
    """The tree drawn as ``vest render`` draws it (Graphviz source)."""


@dataclass(frozen=True, slots=True)
class NodeStatus:
    """A node's status or feedback message changed in a tick (due at ``t_s``)."""

    kind: ClassVar[str] = "status"
    t_s: float
    tree: str
    version: int
    tick: int
    node: int
    status: str
    feedback: str
    carries: Carries = NOTHING
    """What of a person the node's feedback may quote (what the node reads)."""


@dataclass(frozen=True, slots=True)
class ActionStarted:
    """A tree asked a service to act (say, led, servo, read, report); ``action_id``
    pairs it with its :class:`ActionEnded`."""

    kind: ClassVar[str] = "action"
    t_s: float
    action_id: int
    tree: str
    action: str
    args: dict[str, Any]
    carries: Carries = NOTHING
    """What of a person ``args`` were made from (a Say that fills in what was heard)."""


Outcome = Literal["done", "failed", "cut"]
"""How an action ended: done as asked; failed (the service could not, or the safety
envelope refused or stopped it); cut short before it was done (its tree was interrupted,
paused, reloaded or stopped)."""


@dataclass(frozen=True, slots=True)
class ActionEnded:
    """An action's outcome, with why when it was not done."""

    kind: ClassVar[str] = "outcome"
    t_s: float
    action_id: int
    tree: str
    action: str
    args: dict[str, Any]
    started_s: float
    outcome: Outcome
    why: str = ""
    carries: Carries = NOTHING
    """As its :class:`ActionStarted`'s (``why`` may quote the arguments too)."""
    why_carries: Carries = NOTHING
    """What of a person ``why`` quotes besides (a safety refusal's distance or force)."""


TurnKind = Literal["interrupts", "waits", "yields", "tries_again"]


@dataclass(frozen=True, slots=True)
class TurnTaken:
    """One voice at a time: ``tree`` interrupts ``other`` for ``resource``, waits for
    it, yields it (``what`` it lets go), or will try again once it is free."""

    kind: ClassVar[str] = "turn"
    t_s: float
    tree: str
    turn: TurnKind
    resource: str
    other: str
    what: str = ""
    carries: Carries = NOTHING
    """What of a person ``what`` (the action let go, in words) was made from."""

    @property
    def text(self) -> str:
        """As the timeline says it, after the tree's name."""
        if self.turn == "interrupts":
            return f"interrupts {self.other} to use the {self.resource}"
        if self.turn == "waits":
            return f"waits for the {self.resource}: {self.other} has it"
        if self.turn == "tries_again":
            return f"will try again once the {self.resource} is free ({self.other} has it)"
        return f"yields the {self.resource} to {self.other}: not {self.what}"


PressedBy = Literal["page", "key", "scenario", "cloud"]
"""Where a button was pressed: on the buttons page, by its keyboard key, a scenario's press,
or on the cloud's page (remote wizard of oz)."""
ButtonControl = Literal["", "pause", "resume", "stop"]
"""What a control button did ("": none, the button has the robot do something)."""
SafetyKind = Literal["refused", "stopped", "slowed", "held"]
"""refused a move, stopped one under way, slowed one, or held an arm where it is until it
may go back to rest."""


@dataclass(frozen=True, slots=True)
class SafetyAction:
    """The safety envelope refused a move, stopped one under way, or slowed one (the
    tree's action and its outcome follow with the tree's name).

    ``rule`` is the config field that decided (``still_within_mm``, ``stop_above_n``,
    ``joint_limits``...), ``devices`` the sensors it read (or could not trust), ``why``
    the whole reason in words."""

    kind: ClassVar[str] = "safety"
    t_s: float
    action: SafetyKind
    joint: str
    rule: str
    devices: tuple[str, ...]
    why: str
    carries: Carries = NOTHING
    """What of a person ``why`` quotes (the force or distance that decided)."""


@dataclass(frozen=True, slots=True)
class ButtonPressed:
    """The therapist pressed a button (``by``: on the ``page``, a ``key``, or a
    ``scenario``'s ``press``); ``done`` is False when it was not shown then, so nothing was
    done; ``control`` is what a control button did (``pause``, ``resume``, ``stop``: stop
    everything), "" for a button that has the robot do something."""

    kind: ClassVar[str] = "press"
    t_s: float
    label: str
    by: PressedBy
    done: bool = True
    control: ButtonControl = ""
    who: str = ""
    """The cloud account that pressed it (``by`` cloud); "" for a press at the robot."""


@dataclass(frozen=True, slots=True)
class BehaviorsPaused:
    """The therapist paused (``paused``) or resumed the autonomous behaviors."""

    kind: ClassVar[str] = "pause"
    t_s: float
    paused: bool


@dataclass(frozen=True, slots=True)
class DeviceChanged:
    """A device went offline or came back (``/devices/<name>/ok`` changed); ``first``:
    its first report, at start-up."""

    kind: ClassVar[str] = "device"
    t_s: float
    device: str
    ok: bool
    first: bool = False


@dataclass(frozen=True, slots=True)
class Heard:
    """The recognizer heard ``text`` (a ``/speech/heard`` event)."""

    kind: ClassVar[str] = "heard"
    t_s: float
    text: str


@dataclass(frozen=True, slots=True)
class NotUnderstood:
    """A dialog had no rule for what was heard; the robot answered with its fallback
    ("Sorry, I did not understand") when the dialog has one, asked whether it heard the
    rule ``asked`` ("" when it did not ask), or said its ``reprompt``-th reprompt (0 when
    none)."""

    kind: ClassVar[str] = "not_understood"
    t_s: float
    tree: str
    text: str
    why: str
    asked: str = ""
    reprompt: int = 0


@dataclass(frozen=True, slots=True)
class NotListened:
    """Someone spoke while the robot was speaking, and the robot did not listen (its
    microphone is ignored while it speaks, so it never answers its own voice)."""

    kind: ClassVar[str] = "not_listened"
    t_s: float
    from_s: float
    until_s: float
    why: str


@dataclass(frozen=True, slots=True)
class SpokenOver:
    """A person's voice began (``from_s``) while the robot was saying ``saying`` (its
    action ``action_id`` of ``tree``): the robot stopped talking, and the tree's round
    stopped as an interruption stops it. What the person said is heard as any utterance."""

    kind: ClassVar[str] = "spoken_over"
    t_s: float
    tree: str
    action_id: int
    saying: str
    from_s: float
    carries: Carries = NOTHING
    """What of a person ``saying`` was made from (a Say that fills in what was heard)."""


@dataclass(frozen=True, slots=True)
class HandShown:
    """The camera saw ``fingers`` held up (a ``/vision/hand/shown`` event)."""

    kind: ClassVar[str] = "hand"
    t_s: float
    fingers: int


@dataclass(frozen=True, slots=True)
class TreeReloaded:
    """A changed tree file was swapped in, or (``problem``) kept out: the running
    version goes on."""

    kind: ClassVar[str] = "reload"
    t_s: float
    tree: str
    problem: str = ""


@dataclass(frozen=True, slots=True)
class WorldEvent:
    """Something a scenario made happen around the simulated robot."""

    kind: ClassVar[str] = "world"
    t_s: float
    scenario_event: str
    """The scenario event's kind (touch, squeeze, hear, unplug...)."""
    description: str
    value: Any = None


@dataclass(frozen=True, slots=True)
class KeyChanged:
    """A committed blackboard write that says something new: every event, and a state
    key's write when its value changed. ``text`` is the value as JSON."""

    kind: ClassVar[str] = "key"
    t_s: float
    key: str
    value: Any
    text: str
    event: bool
    writer: str
    carries: Carries = NOTHING
    """What of a person the value is or was made from (its key's, or its writer's)."""


@dataclass(frozen=True, slots=True)
class SessionEnded:
    """The session is over (the run ended or was stopped)."""

    kind: ClassVar[str] = "end"
    t_s: float
    facts: dict[str, str] = field(default_factory=dict)


SessionEvent = (
    TreeStarted
    | NodeStatus
    | ActionStarted
    | ActionEnded
    | TurnTaken
    | SafetyAction
    | ButtonPressed
    | BehaviorsPaused
    | DeviceChanged
    | Heard
    | NotUnderstood
    | NotListened
    | SpokenOver
    | HandShown
    | TreeReloaded
    | WorldEvent
    | KeyChanged
    | SessionEnded
)
EVENT_TYPES: tuple[type[SessionEvent], ...] = (
    TreeStarted,
    NodeStatus,
    ActionStarted,
    ActionEnded,
    TurnTaken,
    SafetyAction,
    ButtonPressed,
    BehaviorsPaused,
    DeviceChanged,
    Heard,
    NotUnderstood,
    NotListened,
    SpokenOver,
    HandShown,
    TreeReloaded,
    WorldEvent,
    KeyChanged,
    SessionEnded,
)
KINDS = tuple(event_type.kind for event_type in EVENT_TYPES)


GATE_ONLY = frozenset({"carries", "why_carries"})
"""Fields only the consent gate reads: never told further (no wire, file or page has them)."""


def told_fields(event_type: type[SessionEvent] | SessionEvent) -> tuple[str, ...]:
    """The fields of an event type that readers tell (on the wire, in a file, on a
    page): all but :data:`GATE_ONLY`."""
    return tuple(
        field.name for field in dataclasses.fields(event_type) if field.name not in GATE_ONLY
    )
