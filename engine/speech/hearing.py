"""The robot's hearing on a recording, start to end: VAD -> recognizer -> dialog matcher.

``vest hear`` and ``vest dialogs check`` use it; it is the path a microphone takes,
without the threads.
"""

from __future__ import annotations

import string
from dataclasses import dataclass

from engine.dialogs.model import Dialog, FollowUp, Verdict
from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.speech.recognizer import Recognizer
from engine.speech.vad import SpeechDetector, SpeechProbability
from engine.values.templates import CompiledTemplate

TRAILING_SILENCE_S = 0.5
"""Added after a recording, so speech that runs to its very end still ends."""


def shown_answer(template: CompiledTemplate) -> str:
    """An answer as text with each field as ``[name]`` (filled from the robot's sensors
    only when it answers)."""
    shown = ""
    for literal, field, _, _ in string.Formatter().parse(template.source):
        shown += literal + (f"[{field}]" if field else "")
    return shown


@dataclass(frozen=True)
class Hearing:
    """What the robot made of a recording."""

    heard: str | None
    """The text (utterances joined), None when no speech was found or nothing recognized."""
    verdict: Verdict | None
    answer: str | None
    """The answer (fields shown as ``[name]``), or the fallback; None for neither."""

    def as_json(self, name: str) -> dict[str, object]:
        match = self.verdict.match if self.verdict is not None else None
        return {
            "file": name,
            "heard": self.heard,
            "rule": match.rule.id if match is not None else None,
            "score": round(match.score, 3) if match is not None else None,
            "answer": self.answer,
        }


def utterances(audio: Audio, vad: SpeechProbability) -> list[Audio]:
    """The utterances Silero finds in ``audio``."""
    vad.reset()
    detector = SpeechDetector(vad)
    samples = audio.resampled(SPEECH_RATE_HZ).then(Audio.silence(TRAILING_SILENCE_S)).samples
    found = [u.audio for u in detector.feed(samples)]
    last = detector.flush()
    return found + ([last.audio] if last is not None else [])


def hear(
    audio: Audio,
    vad: SpeechProbability,
    recognizer: Recognizer,
    dialog: Dialog | None,
    follow_up: FollowUp | None = None,
) -> Hearing:
    """What the robot hears in ``audio`` and how ``dialog`` answers it."""
    texts = [recognizer.transcribe(part).text for part in utterances(audio, vad)]
    heard = " ".join(t for t in texts if t) or None
    if heard is None or dialog is None:
        return Hearing(heard, None, None)
    return _judged(heard, dialog, follow_up)


def _judged(heard: str, dialog: Dialog, follow_up: FollowUp | None) -> Hearing:
    verdict = dialog.judge(heard, follow_up)
    if verdict.match is not None:
        return Hearing(heard, verdict, shown_answer(verdict.match.rule.answer))
    otherwise = follow_up.otherwise if follow_up is not None else None
    said = otherwise or dialog.fallback
    return Hearing(heard, verdict, shown_answer(said) if said is not None else None)


def conversation(
    audio: Audio, vad: SpeechProbability, recognizer: Recognizer, dialog: Dialog
) -> list[Hearing]:
    """Each utterance in ``audio`` heard and answered in turn, as the robot would: when an
    answer asked a question (``then:``), the next utterance is heard as its reply. A
    recording without speech is one Hearing of nothing."""
    hearings: list[Hearing] = []
    follow_up: FollowUp | None = None
    for part in utterances(audio, vad):
        text = recognizer.transcribe(part).text
        if not text:
            continue
        hearing = _judged(text, dialog, follow_up)
        hearings.append(hearing)
        match = hearing.verdict.match if hearing.verdict is not None else None
        follow_up = match.rule.follow_up if match is not None else None
    return hearings or [Hearing(None, None, None)]
