"""The robot's hearing on a recording, start to end: VAD -> recognizer -> dialog matcher.

``vest hear`` and ``vest dialogs check`` use it; it is the path a microphone takes,
without the threads.
"""

from __future__ import annotations

import string
from dataclasses import dataclass, replace

from engine.clock import stopwatch
from engine.dialogs.model import Dialog, FollowUp, Verdict
from engine.media.audio import SPEECH_RATE_HZ, Audio, with_noise
from engine.speech.recognizer import Recognizer
from engine.speech.vad import FRAME_SAMPLES, SpeechDetector, SpeechProbability, Utterance
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
    would live on this machine: the silence it waits to be sure the speaker is done, or,
    when longer, the short pause after which it starts recognizing the speech so far plus
    the recognizer and the matcher (measured here). None when nothing was heard."""

    def as_json(self, name: str) -> dict[str, object]:
        match = self.verdict.match if self.verdict is not None else None
        return {
            "file": name,
            "heard": self.heard,
            "rule": match.rule.id if match is not None else None,
            "score": round(match.score, 3) if match is not None else None,
            "answer": self.answer,
            "latency_s": round(self.latency_s, 3) if self.latency_s is not None else None,
        }


@dataclass(frozen=True)
class Part:
    """One utterance as the live robot hears it: the audio it recognizes (the draft's,
    when the draft held all of it) and when that recognition starts (seconds of quiet
    after the last voiced frame)."""

    utterance: Utterance
    heard: Audio
    starts_after_s: float


def utterances(audio: Audio, vad: SpeechProbability) -> list[Utterance]:
    """The utterances Silero finds in ``audio``."""
    return [part.utterance for part in parts(audio, vad)]


def parts(audio: Audio, vad: SpeechProbability) -> list[Part]:
    """The utterances in ``audio``, each with the audio the robot would recognize."""
    vad.reset()
    drafts: list[Utterance] = []
    detector = SpeechDetector(vad, on_pause=drafts.append)
    samples = audio.resampled(SPEECH_RATE_HZ).then(Audio.silence(TRAILING_SILENCE_S)).samples
    found: list[Part] = []
    for at in range(0, len(samples), FRAME_SAMPLES):  # a frame at a time: each its draft
        ended = detector.feed(samples[at : at + FRAME_SAMPLES])
        found += [_part(utterance, drafts) for utterance in ended]
    last = detector.flush()
    return found + ([_part(last, drafts)] if last is not None else [])


def _part(utterance: Utterance, drafts: list[Utterance]) -> Part:
    if utterance.drafted and drafts:
        return Part(utterance, drafts[-1].audio, drafts[-1].quiet_s)
    return Part(utterance, utterance.audio, utterance.quiet_s)


def hear(
    audio: Audio,
    vad: SpeechProbability,
    recognizer: Recognizer,
    dialog: Dialog | None,
    follow_up: FollowUp | None = None,
) -> Hearing:
    """What the robot hears in ``audio`` and how ``dialog`` answers it."""
    texts = [recognizer.transcribe(part.heard).text for part in parts(audio, vad)]
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
    for part in parts(audio, vad):
        started = stopwatch()
        text = recognizer.transcribe(part.heard).text
        if not text:
            continue
        hearing = _judged(text, dialog, follow_up)
        working_s = part.starts_after_s + stopwatch() - started
        hearing = replace(hearing, latency_s=max(part.utterance.quiet_s, working_s))
        hearings.append(hearing)
        match = hearing.verdict.match if hearing.verdict is not None else None
        follow_up = match.rule.follow_up if match is not None else None
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
