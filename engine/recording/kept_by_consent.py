"""What of a session may be kept, by the person's consent (:mod:`engine.privacy.consent`).

The robot hears and sees everything it answers; the recording keeps only what was
consented to:

- ``sensors``: the ``/sensors/`` and ``/vision/`` keys, what the scenario did to the vest
  (touches, squeezes...), and the nodes' feedback messages (which tell what a node saw:
  "a pat on middle_back", "event 1: 5" fingers); without it none of these is kept;
- ``speech_text``: ``/speech/heard``, what a dialog did not understand, what the scenario
  said; without it the fact that someone spoke is kept, never the words: each utterance
  heard is also cut out of every free text the session tells (a node's feedback, "no rule
  matches '...'", an action's arguments that echo it, a tree's ``/vars/``), as written,
  quoted or escaped, where it stands as words of its own (never out of a name or a key).

The robot's own actions (what it said and did, and how each ended), its trees' statuses,
turns, safety decisions and presses are always kept: they are the robot's account, not the
person's. vest keeps no audio and no camera frame of a session at all (``audio`` and
``camera`` consent nothing today).
"""

from __future__ import annotations

import dataclasses
import json
import re
from typing import Any

from engine.blackboard.catalogue import SENSORS_PREFIX, SPEECH_HEARD, VARIABLES_PREFIX
from engine.blackboard.events import EventLog
from engine.privacy.consent import CAPTURES, Consent
from engine.session.events import (
    Heard,
    KeyChanged,
    NodeStatus,
    NotUnderstood,
    SessionEvent,
    WorldEvent,
)

VISION_PREFIX = "/vision/"
WORDS_NOT_KEPT = "(words not kept: no consent for speech as text)"
FREE_TEXT = ("feedback", "args", "why", "what", "text")
"""The fields of a session event that hold free text (never a name or a key)."""
FREE_TEXT_OF_KEYS = ("value", "text")
"""Of a blackboard change, the value (of a tree's own ``/vars/`` key only)."""
_START, _END = r"(?<!\w)(?:", r")(?!\w)"
"""An utterance is cut where it stands as words of its own, not inside another word."""


class KeptByConsent:
    """Turns each session event into what may be kept of it (None: nothing)."""

    def __init__(self, consent: Consent) -> None:
        self.consent = consent
        self._sensors = consent.allows("sensors")
        self._words = consent.allows("speech_text")
        self._heard: re.Pattern[str] | None = None
        """What was heard so far (without consent to keep it), to cut out of any text."""
        self._phrases: set[str] = set()
        self._fields: dict[type, frozenset[str]] = {}

    def kept(self, event: SessionEvent) -> SessionEvent | None:
        if not self._words:
            self._learn(event)
        if isinstance(event, KeyChanged):
            if event.key == SPEECH_HEARD and not self._words:
                return None
            if event.key.startswith((SENSORS_PREFIX, VISION_PREFIX)) and not self._sensors:
                return None
            return self._without_words(event)
        if isinstance(event, Heard) and not self._words:
            return None
        if isinstance(event, NotUnderstood) and not self._words:
            return dataclasses.replace(event, text=WORDS_NOT_KEPT)
        if isinstance(event, WorldEvent):
            if event.scenario_event == "hear":
                if self._words:
                    return event
                spoke = f"someone spoke {WORDS_NOT_KEPT}"
                return dataclasses.replace(event, description=spoke, value=None)
            return event if self._sensors else None
        return self._without_words(event)

    def left_out(self) -> str:
        """What is not kept, in words ('' when everything is)."""
        return ", ".join(CAPTURES[name] for name in self.consent.left_out)

    def _learn(self, event: SessionEvent) -> None:
        """Remembers (in memory only) each phrase heard, to cut it out of later texts."""
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
        """``event`` with its free texts cleared of what may not be kept: every phrase
        heard so far (without consent to speech as text), every node's feedback (without
        consent to sensor readings)."""
        if isinstance(event, NodeStatus) and not self._sensors and event.feedback:
            event = dataclasses.replace(event, feedback="")
        pattern = self._heard
        if pattern is None:
            return event
        fields: tuple[str, ...]
        if isinstance(event, KeyChanged):
            fields = FREE_TEXT_OF_KEYS if event.key.startswith(VARIABLES_PREFIX) else ()
        else:
            fields = FREE_TEXT
        changes: dict[str, Any] = {}
        present = self._fields.get(type(event))
        if present is None:  # its fields, not a property (a turn's text); once a kind
            present = frozenset(field.name for field in dataclasses.fields(event))
            self._fields[type(event)] = present
        for name in fields:
            if name in present:
                value = getattr(event, name)
                cut = _cut(value, pattern)
                if cut is not value:
                    changes[name] = cut
        return dataclasses.replace(event, **changes) if changes else event


def _cut(value: Any, pattern: re.Pattern[str]) -> Any:
    """``value`` with ``pattern`` replaced in every string in it (the same object when
    nothing changed)."""
    if isinstance(value, str):
        cut = pattern.sub(WORDS_NOT_KEPT, value)
        return cut if cut != value else value
    if isinstance(value, dict):
        items = {k: _cut(v, pattern) for k, v in value.items()}
        return items if any(items[k] is not value[k] for k in value) else value
    if isinstance(value, list | tuple):
        cut_items = [_cut(v, pattern) for v in value]
        if any(a is not b for a, b in zip(cut_items, value, strict=True)):
            return type(value)(cut_items)
        return value
    return value
