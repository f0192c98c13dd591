"""The robot's hearing on a recording, start to end: VAD -> recognizer -> dialog matcher.

``vest hear`` and ``vest dialogs check`` use it; it is the path a microphone takes,
without the threads.
"""

from __future__ import annotations

import string
from collections.abc import Callable
from dataclasses import dataclass, replace

from engine.clock import stopwatch
from engine.dialogs.confirming import maybe_meant
from engine.dialogs.model import Dialog, DialogRule, FollowUp, Verdict
from engine.media.audio import SPEECH_RATE_HZ, Audio, Samples, with_noise
from engine.speech.recognizer import Recognizer
from engine.speech.vad import (
    FRAME_SAMPLES,
    SpeechDetector,
    SpeechProbability,
    Utterance,
    speech_detector,
)
from engine.speech.voices import Voice
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
    latency_s: float | None = None
    """Seconds from the end of speech (its last voiced frame) to the intent, as the robot
    would live on this machine: the silence it waits to be sure the speaker is done (shorter
    after a whole turn), or, when longer, the short pause after which it starts recognizing
    the speech so far plus the recognizer and the matcher (measured here). None when nothing
    was heard."""
    asks: DialogRule | None = None
    """The rule the robot asks whether it heard (``answer`` is its ``confirm:`` question)."""

    def as_json(self, name: str) -> dict[str, object]:
        match = self.verdict.match if self.verdict is not None else None
        return {
            "file": name,
            "heard": self.heard,
            "rule": match.rule.id if match is not None else None,
            "score": round(match.score, 3) if match is not None else None,
            "answer": self.answer,
            "asks": self.asks.id if self.asks is not None else None,
            "latency_s": round(self.latency_s, 3) if self.latency_s is not None else None,
        }


@dataclass(frozen=True)
class Part:
    """One utterance as the live robot hears it, on the recording's timeline (seconds from
    its start): its text, where its last voiced frame was, when the robot took it as ended,
    and when its text was ready (recognition timed on this machine)."""

    utterance: Utterance
    text: str
    spoken_until_s: float
    ended_s: float
    ready_s: float

    @property
    def latency_s(self) -> float:
        """Seconds from the last voiced frame to the text."""
        return self.ready_s - self.spoken_until_s


def utterances(audio: Audio, vad: SpeechProbability, *, children: bool = False) -> list[Utterance]:
    """The utterances Silero finds in ``audio`` (the full wait for silence after each;
    ``children``: as the robot listens to children, :func:`speech_detector`)."""
    vad.reset()
    detector = speech_detector(vad, children=children)
    found = detector.feed(
        audio.resampled(SPEECH_RATE_HZ).then(Audio.silence(TRAILING_SILENCE_S)).samples
    )
    last = detector.flush()
    return found + ([last] if last is not None else [])


def overtaking(samples: Samples, vad: SpeechProbability, *, children: bool) -> dict[int, float]:
    """Where speech went on after each draft the detector tells in ``samples`` (16 kHz):
    the draft's end (samples) -> the time speech went on (seconds). A draft never overtaken
    is not in it. The live robot learns it as it happens; on a recording it is known
    before, so :func:`heard_live` can stop a draft's recognition when the live one would
    stop (:class:`~engine.speech.listener.Listener`)."""
    vad.reset()
    told: list[Utterance] = []
    detector = speech_detector(vad, children=children, on_pause=told.append)
    found: dict[int, float] = {}
    for at in range(0, len(samples), FRAME_SAMPLES):
        detector.feed(samples[at : at + FRAME_SAMPLES])
        for draft in [d for d in told if detector.overtaken(d)]:
            found[draft.end_sample] = detector.position / SPEECH_RATE_HZ
            told.remove(draft)
        del told[:-1]  # a draft not overtaken when the next is told never will be
    return found


class _LiveTimeline:
    """The listener's worker on a recording's timeline: one recognition at a time, each
    starting when its audio was told and the worker was free, taking as long as it takes
    here; a draft overtaken by newer speech while it waited is never recognized, and one
    overtaken while it is recognized stops then (as the
    :class:`~engine.speech.listener.Listener` does: ``overtaken``, from :func:`overtaking`);
    a draft that is a whole turn tells the detector when its text is ready."""

    def __init__(
        self,
        detector: SpeechDetector,
        recognizer: Recognizer,
        whole_turn: Callable[[str], bool] | None,
        overtaken: dict[int, float],
    ) -> None:
        self.detector = detector
        self.recognizer = recognizer
        self.whole_turn = whole_turn
        self.overtaken = overtaken
        self.free_s = 0.0
        self.waiting: Utterance | None = None  # a draft told while the worker was busy
        self.draft: tuple[Utterance, str, float] | None = None  # draft, text, ready
        self.whole_at_s: float | None = None

    def at(self, now_s: float) -> None:
        """Time has reached ``now_s``: a waiting draft starts once the worker is free, and
        a whole turn found by then is told."""
        if self.waiting is not None and self.free_s <= now_s:
            self._recognize_draft(self.waiting)
            self.waiting = None
        if self.whole_at_s is not None and self.whole_at_s <= now_s and self.draft:
            self.detector.whole_turn(self.draft[0])
            self.whole_at_s = None

    def drafted(self, draft: Utterance) -> None:
        if self.free_s > draft.end_sample / SPEECH_RATE_HZ:
            self.waiting = draft  # overtakes any draft still waiting
            self.draft, self.whole_at_s = None, None
        else:
            self._recognize_draft(draft)

    def ended(self, utterance: Utterance) -> Part:
        ended_s = utterance.end_sample / SPEECH_RATE_HZ
        self.waiting = None  # overtaken by the end: never recognized
        if utterance.drafted and self.draft is not None:
            text, ready_s = self.draft[1], max(ended_s, self.draft[2])
        else:
            text, ready_s = self._recognized(utterance)
        self.draft, self.whole_at_s = None, None
        return Part(utterance, text, ended_s - utterance.quiet_s, ended_s, ready_s)

    def _recognize_draft(self, draft: Utterance) -> None:
        text, ready_s = self._recognized(draft, self.overtaken.get(draft.end_sample))
        self.draft = (draft, text, ready_s)
        whole = bool(text) and self.whole_turn is not None and self.whole_turn(text)
        self.whole_at_s = ready_s if whole else None

    def _recognized(
        self, utterance: Utterance, overtaken_s: float | None = None
    ) -> tuple[str, float]:
        """Its text and when it was ready; a draft overtaken at ``overtaken_s`` is
        abandoned once the worker's time passes it."""
        begins_s = max(self.free_s, utterance.end_sample / SPEECH_RATE_HZ)
        started = stopwatch()

        def abandon() -> bool:
            return overtaken_s is not None and begins_s + stopwatch() - started >= overtaken_s

        text = self.recognizer.transcribe(utterance.audio, abandon=abandon).text
        self.free_s = begins_s + stopwatch() - started
        return text, self.free_s


def heard_live(
    audio: Audio,
    vad: SpeechProbability,
    recognizer: Recognizer,
    whole_turn: Callable[[str], bool] | None = None,
    *,
    children: bool = False,
) -> list[Part]:
    """Each utterance in ``audio`` as the live :class:`~engine.speech.listener.Listener`
    hears it: drafts recognized during the wait for silence, a whole turn (``whole_turn``)
    ending it sooner, one recognition at a time, at this machine's speed; ``children``:
    with the wait for silence of a robot that hears children (:func:`speech_detector`)."""
    samples = audio.resampled(SPEECH_RATE_HZ).then(Audio.silence(TRAILING_SILENCE_S)).samples
    overtaken = overtaking(samples, vad, children=children)
    vad.reset()
    drafts: list[Utterance] = []
    detector = speech_detector(vad, children=children, on_pause=drafts.append)
    live = _LiveTimeline(detector, recognizer, whole_turn, overtaken)
    found: list[Part] = []
    for at in range(0, len(samples), FRAME_SAMPLES):  # a frame at a time, as a microphone
        live.at(at / SPEECH_RATE_HZ)
        ended = detector.feed(samples[at : at + FRAME_SAMPLES])
        for draft in drafts:
            live.drafted(draft)
        drafts.clear()
        found += [live.ended(utterance) for utterance in ended]
    last = detector.flush()
    return found + ([live.ended(last)] if last is not None else [])


def hear(
    audio: Audio,
    vad: SpeechProbability,
    recognizer: Recognizer,
    dialog: Dialog | None,
    follow_up: FollowUp | None = None,
    whole_turn: Callable[[str], bool] | None = None,
    *,
    children: bool = False,
) -> Hearing:
    """What the robot hears in ``audio`` and how ``dialog`` answers it (``whole_turn``,
    ``children``: as for :func:`heard_live`)."""
    parts = heard_live(audio, vad, recognizer, whole_turn, children=children)
    texts = [part.text for part in parts]
    heard = " ".join(t for t in texts if t) or None
    if heard is None or dialog is None:
        return Hearing(heard, None, None)
    return _judged(heard, dialog, follow_up)


def _judged(heard: str, dialog: Dialog, follow_up: FollowUp | None) -> Hearing:
    """What the dialog makes of ``heard``: the answer, the question that confirms a rule it
    is only like (:mod:`engine.dialogs.confirming`), or the sorry."""
    verdict = dialog.judge(heard, follow_up)
    if verdict.match is not None:
        return Hearing(heard, verdict, shown_answer(verdict.match.rule.answer))
    maybe = maybe_meant(dialog, heard, follow_up)
    if maybe is not None and maybe.confirm is not None:
        return Hearing(heard, verdict, shown_answer(maybe.confirm), asks=maybe)
    otherwise = follow_up.otherwise if follow_up is not None else None
    said = otherwise or dialog.fallback
    return Hearing(heard, verdict, shown_answer(said) if said is not None else None)


def conversation(
    audio: Audio,
    vad: SpeechProbability,
    recognizer: Recognizer,
    dialog: Dialog,
    whole_turn: Callable[[str], bool] | None = None,
    *,
    children: bool = False,
) -> list[Hearing]:
    """Each utterance in ``audio`` heard and answered in turn, as the robot would: when an
    answer asked a question (``then:``), the next utterance is heard as its reply. A
    recording without speech is one Hearing of nothing. ``whole_turn``, ``children``: as
    for :func:`heard_live`."""
    hearings: list[Hearing] = []
    follow_up: FollowUp | None = None
    for part in heard_live(audio, vad, recognizer, whole_turn, children=children):
        if not part.text:
            continue
        started = stopwatch()
        hearing = _judged(part.text, dialog, follow_up)
        hearing = replace(hearing, latency_s=part.latency_s + stopwatch() - started)
        hearings.append(hearing)
        match = hearing.verdict.match if hearing.verdict is not None else None
        follow_up = match.rule.follow_up if match is not None else None
        if hearing.asks is not None:
            follow_up = hearing.asks.confirmed
    return hearings or [Hearing(None, None, None)]


def spoken(voice: Voice, text: str, speed: float = 1.0, snr_db: float | None = None) -> Audio:
    """``text`` said by ``voice`` at ``speed`` as a microphone would take it in: with
    0.3 s of silence around it, noise at ``snr_db`` dB SNR (None: none), at half level."""
    speech = voice.synthesize(text, speed=speed)
    pad = Audio.silence(0.3, speech.rate_hz)
    audio = pad.then(speech).then(pad)
    if snr_db is not None:
        audio = with_noise(audio, snr_db, seed=len(text))
    return audio.scaled(0.5)
