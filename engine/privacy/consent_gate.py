"""The consent gate: what of a session may pass each way out of the robot, decided here.

Everything a session tells passes one gate before it reaches anyone
(:class:`ConsentGates`): the robot's trees, services and sensors publish on the session
stream, and the gate alone is subscribed to it; every reader subscribes to one of its two
exits instead:

- :attr:`Exit.KEPT`: what is written on the site's disks or shown on its screens (the
  recording, and so the report and the export; the live view; the terminal's timeline and
  ``--json``; Foxglove's live server);
- :attr:`Exit.SENT`: what leaves the robot (the cloud's telemetry and command results; a
  ROS 2 graph). It passes what the kept exit passes, and readings and words only when the
  person consented to ``cloud_telemetry`` as well.

Readings (consent's ``sensors``) and what was said (``speech_text``) are found by what
they were made from, not by where they stand: each event says what of a person its text
is made of (``carries``, filled by the node, service or blackboard that made it), so a
Say that fills in part of an utterance (``{/vars/heard:.15}``), a variable fed by what was
heard, a turn that quotes a Say's text, an outcome's reason that quotes a distance, all
count as the words and readings themselves. As a second line, every utterance heard is
cut out of every free text the session tells, however it is quoted, where it stands as
words of its own.

The robot's own account (that it acted, what it said of its own, its trees' statuses,
turns, presses, devices) always passes: consent decides what is kept and sent, never
what the robot does.
"""

from __future__ import annotations

import dataclasses
import enum
import json
import re
from typing import Any

from engine.blackboard.catalogue import (
    NOTHING,
    READINGS,
    SPEECH_HEARD,
    VARIABLES_PREFIX,
    WORDS,
    Carries,
    captures_of,
)
from engine.blackboard.events import EventLog
from engine.privacy.consent import CAPTURES, Consent
from engine.session.events import (
    ActionEnded,
    ActionStarted,
    HandShown,
    Heard,
    KeyChanged,
    NodeStatus,
    NotUnderstood,
    SafetyAction,
    SessionEvent,
    SpokenOver,
    TurnTaken,
    WorldEvent,
)
from engine.session.stream import SessionStream

WORDS_NOT_KEPT = "(words not kept: no consent for speech as text)"
READINGS_NOT_KEPT = "(not kept: no consent for sensor readings)"
NOT_SENT = "(not sent: no consent for telemetry to the cloud)"
RESULT_WITHHELD = (
    "not sent: the person's consent does not cover what this result holds leaving the robot"
)
"""A command's result, in place of one made of readings or words the person did not
consent to send."""
FREE_TEXT = ("feedback", "args", "why", "what", "text")
"""The fields of a session event that hold free text (never a name or a key)."""
ACT_ARGS = frozenset({"joint", "rest", "id", "status", "sensor", "volume"})
"""An action's arguments that say which act it was, never what it was made of."""
_START, _END = r"(?<!\w)(?:", r")(?!\w)"
"""An utterance is cut where it stands as words of its own, not inside another word."""


class Exit(enum.Enum):
    """Which way out of the robot."""

    KEPT = "kept on this site"
    SENT = "sent off the robot"


class ConsentGate:
    """Turns each session event into what of it may pass ``exit`` under ``consent``
    (None: nothing). Tells what it cannot pass in words (:meth:`left_out`)."""

    def __init__(self, consent: Consent, exit: Exit = Exit.KEPT) -> None:
        self.consent = consent
        self.exit = exit
        leaves = exit is Exit.KEPT or consent.allows("cloud_telemetry")
        self.allowed: Carries = (
            frozenset(c for c in (READINGS, WORDS) if consent.allows(c)) if leaves else NOTHING
        )
        """What of a person passes: readings, words, both or neither."""
        self._readings = READINGS in self.allowed
        self._words = WORDS in self.allowed
        self._cut_off = WORDS_NOT_KEPT if exit is Exit.KEPT or leaves else NOT_SENT
        self._heard: re.Pattern[str] | None = None
        """Every utterance heard so far (held in memory only), to cut out of any text."""
        self._phrases: set[str] = set()
        self._fields: dict[type, frozenset[str]] = {}

    # -- what passes -------------------------------------------------------------------------
    def allows(self, carries: Carries) -> bool:
        """Whether a value made from ``carries`` of a person may pass."""
        return carries <= self.allowed

    def withheld(self, carries: Carries) -> str:
        """What a text made from ``carries`` reads as when it may not pass."""
        if self.exit is Exit.SENT and not self.consent.allows("cloud_telemetry"):
            return NOT_SENT
        return WORDS_NOT_KEPT if WORDS in carries - self.allowed else READINGS_NOT_KEPT

    def lets_result_out(self, result: Any, carries: Carries) -> bool:
        """Whether a command's ``result`` (made from ``carries`` of a person) may pass;
        as a second line, a result that holds a sensor key's value is a reading."""
        return self.allows(carries | _captured_in(result))

    def left_out(self) -> str:
        """What is not kept, in words ('' when everything is)."""
        return ", ".join(CAPTURES[name] for name in self.consent.left_out)

    def passed(self, event: SessionEvent) -> SessionEvent | None:
        """What of ``event`` may pass this exit (None: nothing)."""
        self.learn(event)
        kept = self._by_kind(event)
        return self._without_words(kept) if kept is not None else None

    def _by_kind(self, event: SessionEvent) -> SessionEvent | None:
        if isinstance(event, KeyChanged):
            carries = captures_of(event.key) | event.carries
            return event if self.allows(carries) else None
        if isinstance(event, Heard):
            return event if self._words else None
        if isinstance(event, HandShown):
            return event if self._readings else None
        if isinstance(event, NotUnderstood):
            return event if self._words else dataclasses.replace(event, text=self._cut_off, why="")
        if isinstance(event, WorldEvent):
            if event.scenario_event != "hear":
                return event if self._readings else None
            if self._words:
                return event
            spoke = f"someone spoke {self._cut_off}"
            return dataclasses.replace(event, description=spoke, value=None)
        if isinstance(event, NodeStatus):
            if event.feedback and not (self._readings and self.allows(event.carries)):
                # a node's feedback tells what it saw: never without consent to readings
                shown = "" if not self._readings else self.withheld(event.carries)
                return dataclasses.replace(event, feedback=shown)
            return event
        if isinstance(event, ActionStarted):
            carries = event.carries | _captured_in(event.args)  # a result of readings, too
            if self.allows(carries):
                return event
            withheld = self._act_only(event.args, carries)
            return dataclasses.replace(event, args=withheld, carries=carries)
        if isinstance(event, ActionEnded):
            return self._ended(event)
        if isinstance(event, TurnTaken):
            if event.what and not self.allows(event.carries):
                return dataclasses.replace(event, what=self.withheld(event.carries))
            return event
        if isinstance(event, SpokenOver) and not self.allows(event.carries):
            return dataclasses.replace(event, saying=self.withheld(event.carries))
        if isinstance(event, SafetyAction) and not self.allows(event.carries):
            why = f"by the rule {event.rule} {self.withheld(event.carries)}"
            return dataclasses.replace(event, why=why)
        return event

    def _ended(self, event: ActionEnded) -> ActionEnded:
        args, why = event.args, event.why
        carries = event.carries | _captured_in(event.args)
        if not self.allows(carries):
            args = self._act_only(event.args, carries)
            for name, value in event.args.items():  # a reason that quotes the act's text
                if isinstance(value, str) and value and name not in ACT_ARGS:
                    why = why.replace(value, self.withheld(carries))
        if why and not self.allows(event.why_carries):
            why = self.withheld(event.why_carries)
        if args is event.args and why is event.why:
            return event
        return dataclasses.replace(event, args=args, why=why, carries=carries)

    def _act_only(self, args: dict[str, Any], carries: Carries) -> dict[str, Any]:
        """An action's arguments with what was made of a person withheld: which act it was
        stays (the joint, the command's id), what it carried reads as withheld."""
        shown = self.withheld(carries)
        return {name: value if name in ACT_ARGS else shown for name, value in args.items()}

    # -- what was heard, cut out of every text -------------------------------------------------
    def learn(self, event: SessionEvent) -> None:
        """Remembers (in memory only) each phrase heard, to cut it out of later texts
        (without consent to speech as text; told every event, passed on or not)."""
        if self._words:
            return
        heard: Any = None
        if isinstance(event, KeyChanged) and event.key == SPEECH_HEARD:
            heard = event.value
            if isinstance(heard, EventLog):  # an event key: its latest event's value
                heard = heard.latest.value if heard.latest is not None else None
        elif isinstance(event, Heard | NotUnderstood):
            heard = event.text
        elif isinstance(event, WorldEvent) and event.scenario_event == "hear":
            heard = event.value.get("text") if isinstance(event.value, dict) else None
        if not isinstance(heard, str) or not heard.strip() or heard in self._phrases:
            return
        self._phrases.add(heard)
        forms: set[str] = set()
        for phrase in {heard, heard.strip()}:  # as said, quoted (repr) and in JSON
            forms |= {phrase, repr(phrase)[1:-1], json.dumps(phrase)[1:-1]}
            forms.add(json.dumps(phrase, ensure_ascii=False)[1:-1])
        alternatives = "|".join(re.escape(f) for f in sorted(forms - {""}, key=len, reverse=True))
        if self._heard is not None:
            alternatives = f"{self._heard.pattern[len(_START) : -len(_END)]}|{alternatives}"
        self._heard = re.compile(f"{_START}{alternatives}{_END}", re.IGNORECASE)

    def _without_words(self, event: SessionEvent) -> SessionEvent:
        """``event`` with every phrase heard so far cut out of its free texts (without
        consent to speech as text)."""
        pattern = self._heard
        if pattern is None:
            return event
        fields: tuple[str, ...]
        if isinstance(event, KeyChanged):
            fields = ("value", "text") if event.key.startswith(VARIABLES_PREFIX) else ()
        else:
            fields = FREE_TEXT
        present = self._fields.get(type(event))
        if present is None:  # its fields, not a property (a turn's text); once a kind
            present = frozenset(field.name for field in dataclasses.fields(event))
            self._fields[type(event)] = present
        changes: dict[str, Any] = {}
        for name in fields:
            if name in present:
                value = getattr(event, name)
                cut = _cut(value, pattern, self._cut_off)
                if cut is not value:
                    changes[name] = cut
        return dataclasses.replace(event, **changes) if changes else event


def _captured_in(value: Any) -> Carries:
    """What of a person a result holds by its keys (``{"/sensors/force/left_n": 6.5}``)."""
    found: set[str] = set()
    if isinstance(value, dict):
        for key, item in value.items():
            found |= captures_of(str(key)) | _captured_in(item)
    elif isinstance(value, list | tuple):
        for item in value:
            found |= _captured_in(item)
    return frozenset(found) if found else NOTHING


def _cut(value: Any, pattern: re.Pattern[str], instead: str) -> Any:
    """``value`` with ``pattern`` replaced by ``instead`` in every string in it (the same
    object when nothing changed)."""
    if isinstance(value, str):
        cut = pattern.sub(instead, value)
        return cut if cut != value else value
    if isinstance(value, dict):
        items = {k: _cut(v, pattern, instead) for k, v in value.items()}
        return items if any(items[k] is not value[k] for k in value) else value
    if isinstance(value, list | tuple):
        cut_items = [_cut(v, pattern, instead) for v in value]
        if any(a is not b for a, b in zip(cut_items, value, strict=True)):
            return type(value)(cut_items)
        return value
    return value


class ConsentGates:
    """The one gate in front of a session: subscribed alone to the robot's stream
    (``source``), it tells each exit's stream what may pass it. Readers subscribe to
    :attr:`kept` or :attr:`sent`, never to the robot's stream."""

    def __init__(self, source: SessionStream, consent: Consent) -> None:
        self.consent = consent
        self.kept = source.branch()
        """What is kept on the site's disks or shown on its screens."""
        self.sent = source.branch()
        """What leaves the robot (the cloud, a ROS 2 graph)."""
        self.keeping = ConsentGate(consent, Exit.KEPT)
        self.sending = ConsentGate(consent, Exit.SENT)
        source.subscribe(self, relay=True)

    def gate(self, exit: Exit) -> ConsentGate:
        """The gate of ``exit`` (what a reader that decides on values asks)."""
        return self.keeping if exit is Exit.KEPT else self.sending

    def on_event(self, event: SessionEvent) -> None:
        for stream, gate in ((self.kept, self.keeping), (self.sent, self.sending)):
            if not stream.wants(event.kind):
                gate.learn(event)  # what was heard is cut from what it passes later
                continue
            passed = gate.passed(event)
            if passed is not None:
                stream.publish(passed)
