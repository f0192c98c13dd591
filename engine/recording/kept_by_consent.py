"""What of a session may be kept, by the person's consent (:mod:`engine.privacy.consent`).

The robot hears and sees everything it answers; the recording keeps only what was
consented to:

- ``sensors``: the ``/sensors/`` and ``/vision/`` keys, and what the scenario did to the
  vest (touches, squeezes...); without it none of these is kept;
- ``speech_text``: ``/speech/heard``, what a dialog did not understand, what the scenario
  said; without it the fact that someone spoke is kept, never the words.

The robot's own actions (what it said and did, and how each ended), its trees' statuses,
turns, safety decisions and presses are always kept: they are the robot's account, not the
person's. vest keeps no audio and no camera frame of a session at all (``audio`` and
``camera`` consent nothing today).
"""

from __future__ import annotations

import dataclasses

from engine.blackboard.catalogue import SENSORS_PREFIX, SPEECH_HEARD
from engine.privacy.consent import CAPTURES, Consent
from engine.session.events import KeyChanged, NotUnderstood, SessionEvent, WorldEvent

VISION_PREFIX = "/vision/"
WORDS_NOT_KEPT = "(words not kept: no consent for speech as text)"


class KeptByConsent:
    """Turns each session event into what may be kept of it (None: nothing)."""

    def __init__(self, consent: Consent) -> None:
        self.consent = consent
        self._sensors = consent.allows("sensors")
        self._words = consent.allows("speech_text")

    def kept(self, event: SessionEvent) -> SessionEvent | None:
        if isinstance(event, KeyChanged):
            if event.key == SPEECH_HEARD and not self._words:
                return None
            if event.key.startswith((SENSORS_PREFIX, VISION_PREFIX)) and not self._sensors:
                return None
            return event
        if isinstance(event, NotUnderstood) and not self._words:
            return dataclasses.replace(event, text=WORDS_NOT_KEPT)
        if isinstance(event, WorldEvent):
            if event.scenario_event == "hear":
                if self._words:
                    return event
                return dataclasses.replace(
                    event, description=f"someone spoke {WORDS_NOT_KEPT}", value=None
                )
            return event if self._sensors else None
        return event

    def left_out(self) -> str:
        """What is not kept, in words ('' when everything is)."""
        return ", ".join(CAPTURES[name] for name in self.consent.left_out)
