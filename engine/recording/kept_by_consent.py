"""What of a session may be kept, by the person's consent (:mod:`engine.privacy.consent`).

The robot hears and sees everything it answers; the recording keeps only what was
consented to:

- ``sensors``: the ``/sensors/`` and ``/vision/`` keys, and what the scenario did to the
  vest (touches, squeezes...); without it none of these is kept;
- ``speech_text``: ``/speech/heard``, what a dialog did not understand, what the scenario
  said; without it the fact that someone spoke is kept, never the words: what was heard
  is also cut out of every other text the session tells (a node's feedback, "no rule
  matches '...'", an action's arguments that echo it), since the robot heard it first.

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

from engine.blackboard.catalogue import SENSORS_PREFIX, SPEECH_HEARD
from engine.blackboard.events import EventLog
from engine.privacy.consent import CAPTURES, Consent
from engine.session.events import (
    Heard,
    KeyChanged,
    NotUnderstood,
    SessionEvent,
    WorldEvent,
)

VISION_PREFIX = "/vision/"
WORDS_NOT_KEPT = "(words not kept: no consent for speech as text)"


class KeptByConsent:
    """Turns each session event into what may be kept of it (None: nothing)."""

    def __init__(self, consent: Consent) -> None:
        self.consent = consent
        self._sensors = consent.allows("sensors")
        self._words = consent.allows("speech_text")
        self._heard: re.Pattern[str] | None = None
        """What was heard so far (without consent to keep it), to cut out of any text."""
        self._phrases: set[str] = set()

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
        if not isinstance(heard, str) or len(heard.strip()) < 2 or heard in self._phrases:
            return
        self._phrases.add(heard)
        forms = sorted({heard, json.dumps(heard)[1:-1]}, key=len, reverse=True)  # and as JSON
        alternatives = "|".join(re.escape(form) for form in forms)
        if self._heard is not None:
            alternatives = f"{self._heard.pattern}|{alternatives}"
        self._heard = re.compile(alternatives, re.IGNORECASE)

    def _without_words(self, event: SessionEvent) -> SessionEvent:
        """``event`` with every phrase heard so far cut out of its texts."""
        pattern = self._heard
        if pattern is None or not dataclasses.is_dataclass(event):
            return event
        changes: dict[str, Any] = {}
        for field in dataclasses.fields(event):
            value = getattr(event, field.name)
            cut = _cut(value, pattern)
            if cut is not value:
                changes[field.name] = cut
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
