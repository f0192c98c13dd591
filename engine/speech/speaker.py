"""The robot's voice on its speaker: one utterance at a time, sentence by sentence.

``say`` queues an utterance and returns a job at once. A worker synthesizes the first
sentence, starts playing it, synthesizes the next while it plays, and so on; the job is
done when the last sentence has played (on the clock), and cancelling it stops the sound.
The speaker is one resource: a second tree's utterance waits until the first is done.
While it speaks (and :data:`TAIL_S` after), :class:`SelfHearing` tells the listener to
ignore the microphone.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from concurrent.futures import CancelledError
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from engine.clock import Clock, ClockEvent
from engine.errors import ServiceError
from engine.media.audio import SPEECH_RATE_HZ, Audio, Samples
from engine.services.jobs import Job
from engine.speech.settling import Settling
from engine.speech.voices import Voice, VoiceError, sentences

log = logging.getLogger(__name__)
TAIL_S = 0.4
"""The microphone stays deaf this long after the robot stops speaking (room echo)."""


class Playback(Protocol):
    """Where the sound goes: a sound card, the simulated room."""

    def start(self, audio: Audio, at_s: float) -> None:
        """Play ``audio`` from ``at_s`` (clock seconds; a sound card plays it after what
        is playing); return at once. AudioDeviceError (a RuntimeError) when it cannot."""
        ...

    def stop(self, at_s: float) -> None:
        """Silence from ``at_s`` (clock seconds: when the robot decided to stop; a sound
        card stops now)."""
        ...


class SelfHearing:
    """When the robot speaks and what it plays (clock seconds), so the listener knows when
    the microphone hears the robot (then and ``tail_s`` after, the room's echo) and can
    take that voice out of it (:meth:`reference`)."""

    def __init__(self, tail_s: float = TAIL_S) -> None:
        self.tail_s = tail_s
        self._spans: list[list[float]] = []
        self._played: list[tuple[int, Samples]] = []  # (first sample, 16 kHz samples)
        self._lock = threading.Lock()

    def speaking(self, from_s: float, until_s: float = float("inf")) -> None:
        """The robot speaks from ``from_s`` until ``until_s`` (not known yet: for ever)."""
        with self._lock:
            if self._spans and self._spans[-1][0] == from_s:
                self._spans[-1][1] = until_s
            else:
                self._spans = [*self._spans[-7:], [from_s, until_s]]

    def played(self, audio: Audio, at_s: float) -> None:
        """The speaker plays ``audio`` from ``at_s``: the voice the microphone will hear."""
        samples = audio.resampled(SPEECH_RATE_HZ).samples
        with self._lock:
            self._played = [*self._played[-15:], (_sample_at(at_s), samples)]

    def quiet(self, at_s: float) -> None:
        """The robot stopped speaking at ``at_s`` (cut short, or done)."""
        with self._lock:
            if self._spans:
                self._spans[-1][1] = min(self._spans[-1][1], at_s)
            cut = _sample_at(at_s)
            self._played = [
                (start, samples[: max(0, cut - start)]) for start, samples in self._played
            ]

    def deaf_at(self, at_s: float) -> bool:
        """True when sound at ``at_s`` may be the robot's own voice (or its echo)."""
        with self._lock:
            return any(start <= at_s < end + self.tail_s for start, end in self._spans)

    def reference(self, from_s: float, count: int) -> Samples:
        """What the speaker played over ``count`` samples (16 kHz) from ``from_s``:
        silence where it played nothing."""
        first = _sample_at(from_s)
        mixed = np.zeros(count, dtype=np.float32)
        with self._lock:
            for start, samples in self._played:
                lo, hi = max(first, start), min(first + count, start + len(samples))
                if lo < hi:
                    mixed[lo - first : hi - first] += samples[lo - start : hi - start]
        return mixed


def _sample_at(at_s: float) -> int:
    return round(at_s * SPEECH_RATE_HZ)


class SpeechJob:
    """One utterance: queued, then spoken; ``cancel`` stops it wherever it is.

    Done when the worker finished it, or once the clock reaches ``ends_s`` (known when its
    last sentence started playing): on a virtual clock that makes it done at the same tick
    on every machine, however long the worker takes to notice.
    """

    def __init__(
        self, text: str, volume: float, clock: Clock, *, interruptible: bool = True
    ) -> None:
        self.text = text
        self.volume = volume
        self.interruptible = interruptible
        """Whether a person's voice may stop it (False: a sentence that must finish)."""
        self.hushed = False
        """A person spoke over it: its sound stopped, and it waits to be cancelled (by
        the halt of its tree) rather than end as if it had been said."""
        self.clock = clock
        self.requested_s = clock.now()
        self.stop: ClockEvent = clock.event()
        self.cancelled = False
        self.cancelled_s = float("inf")
        """When it was cancelled (clock seconds): its sound stops there, wherever the
        worker is when it notices."""
        self.ends_s: float | None = None
        self.last_sentence_s: float | None = None
        """When its last sentence began to play (clock seconds; None: not yet)."""
        self._done = threading.Event()
        self._error: BaseException | None = None

    def done(self) -> bool:
        if self._done.is_set() or self.cancelled:
            return True
        return self.ends_s is not None and self.clock.now() >= self.ends_s

    def error(self) -> BaseException | None:
        if self.cancelled:
            return CancelledError("cancelled")
        return self._error if self._done.is_set() else None

    def result(self) -> Any:
        return None

    def cancel(self) -> None:
        if not self.cancelled:  # the first cancel says when (its tree was halted then)
            self.cancelled_s = self.clock.now()
        self.cancelled = True
        self.stop.set()

    def finish(self, error: BaseException | None = None) -> None:
        self._error = error
        self._done.set()


@dataclass
class Utterance:
    """What was said, for whoever keeps the robot's audio (``--audio-out``)."""

    text: str
    audio: Audio
    started_s: float


class Speaker:
    """The :class:`~engine.services.interfaces.Speech` service on a real voice and speaker.

    ``voice`` speaks; when it fails, ``fallback_voice`` does (espeak-ng). ``speed`` and
    ``volume`` (0..1) are the profile's. ``on_utterance`` hears each finished utterance.
    ``instant_synthesis`` (on a virtual clock) starts the sound when it was asked for, as
    if synthesis took no time, so a run does not depend on the machine's speed.
    """

    def __init__(
        self,
        voice: Voice,
        playback: Playback,
        clock: Clock,
        *,
        fallback_voice: Voice | None = None,
        self_hearing: SelfHearing | None = None,
        speed: float = 1.0,
        volume: float = 1.0,
        on_utterance: Callable[[Utterance], None] | None = None,
        settling: Settling | None = None,
        instant_synthesis: bool = False,
    ) -> None:
        self.voice = voice
        self.instant_synthesis = instant_synthesis
        self._free_from_s = float("-inf")
        self.fallback_voice = fallback_voice
        self.playback = playback
        self.clock = clock
        self.self_hearing = self_hearing or SelfHearing()
        self.speed = speed
        self.volume = volume
        self.on_utterance = on_utterance
        self.settling = settling or Settling()
        self._waits_until_s: float | None = None
        self._queue: queue.Queue[SpeechJob | None] = queue.Queue()
        self._thread: threading.Thread | None = None
        self._current: SpeechJob | None = None

    def say(self, text: str, *, volume: float | None = None, interruptible: bool = True) -> Job:
        volume = self.volume if volume is None else volume
        job = SpeechJob(text, volume, self.clock, interruptible=interruptible)
        self._queue.put(job)
        if self._thread is None:
            self.start()
        return job

    def start(self) -> None:
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="speaker", daemon=True)
            self._thread.start()

    def close(self) -> None:
        """Stop speaking and end the worker; queued utterances are cancelled."""
        current = self._current
        if current is not None:
            current.cancel()
        if self._thread is not None:
            self._queue.put(None)
            self._thread.join(timeout=5.0)
            self._thread = None
        while not self._queue.empty():
            job = self._queue.get_nowait()
            if job is not None:
                job.finish(CancelledError("the speaker was closed"))

    def hush(self) -> SpeechJob | None:
        """A person spoke over the robot: silence the utterance playing now, if it may be
        interrupted, and return its job (None: nothing that may be interrupted plays). The
        job stays unfinished until it is cancelled (its tree is halted, the robot's other
        actions of the round with it), so no tree takes it for said."""
        current = self._current
        now_s = self.clock.now()
        if current is None or not current.interruptible or current.done() or current.hushed:
            return None
        if not self.self_hearing.deaf_at(now_s):
            return None  # still being made: nothing of it was heard yet
        current.hushed = True
        self.playback.stop(now_s)
        self.self_hearing.quiet(now_s)
        self._free_from_s = min(self._free_from_s, now_s)
        return current

    def settled(self) -> bool:
        """Nothing to do now: idle with nothing queued, or waiting on the clock for a sound
        that is still playing (what is queued behind it waits too)."""
        waits = self._waits_until_s
        current = self._current
        if current is not None and current.cancelled and waits is not None:
            return False  # its worker has yet to stop the sound and take the next
        if waits is not None:
            return self.clock.now() < waits
        return self._queue.unfinished_tasks == 0

    def _state(self, waits_until_s: float | None = None) -> None:
        self._waits_until_s = waits_until_s
        self.settling.changed()

    def _run(self) -> None:
        while True:
            job = self._queue.get()
            self._current = job
            if job is None:
                self._queue.task_done()
                return
            try:
                self._speak(job)
            except CancelledError as error:
                job.finish(error)
            except Exception as error:  # a voice or a sound card that failed
                words = len(job.text.split())  # never the words: they may quote a person
                log.warning("could not say a sentence of %d words: %s", words, error)
                job.finish(ServiceError(str(error)))
            else:
                job.finish()
            finally:
                self._queue.task_done()
                self.settling.changed()

    def _synthesize(self, sentence: str) -> Audio:
        try:
            return self.voice.synthesize(sentence, speed=self.speed)
        except VoiceError:
            if self.fallback_voice is None:
                raise
            log.warning(
                "voice %s failed; speaking with %s", self.voice.name, self.fallback_voice.name
            )
            return self.fallback_voice.synthesize(sentence, speed=self.speed)

    def _speak(self, job: SpeechJob) -> None:
        said: list[Audio] = []
        started_s = ends_s = self.clock.now()
        try:
            parts = sentences(job.text)
            for index, sentence in enumerate(parts):
                if job.cancelled:
                    raise CancelledError("cancelled")
                if job.hushed:  # the rest is not said; it waits for its cancel
                    ends_s = self._free_from_s = min(self._free_from_s, self.clock.now())
                    break
                audio = self._synthesize(sentence).scaled(job.volume)
                ready_s = job.requested_s if self.instant_synthesis else self.clock.now()
                if not said:
                    started_s = ends_s = max(ready_s, self._free_from_s)
                at_s = max(ends_s, ready_s)
                self.playback.start(audio, at_s)  # the next is synthesized while it plays
                self.self_hearing.played(audio, at_s)
                if not said:  # only sound that really plays makes the microphone deaf
                    self.self_hearing.speaking(started_s)
                said.append(audio)
                ends_s = at_s + audio.seconds
                if index == len(parts) - 1:
                    job.last_sentence_s = at_s
                    job.ends_s = self._free_from_s = ends_s
                    self.self_hearing.speaking(started_s, ends_s)
            self._wait_until(ends_s, job)
        finally:
            if said:
                self.self_hearing.quiet(min(ends_s, self.clock.now(), job.cancelled_s))
            if job.cancelled:  # what was queued after it may start when it stopped
                self._free_from_s = min(self._free_from_s, job.cancelled_s)
        if self.on_utterance is not None and said:
            audio = said[0]
            for more in said[1:]:
                audio = audio.then(more)
            self.on_utterance(Utterance(job.text, audio, started_s))

    def _wait_until(self, ends_s: float, job: SpeechJob) -> None:
        """Until the sound has played, on the clock."""
        self._state(waits_until_s=ends_s)
        try:
            while self.clock.now() < ends_s and not job.cancelled:
                self.clock.wait(job.stop, ends_s - self.clock.now())
            if job.cancelled:
                self.playback.stop(job.cancelled_s)
                raise CancelledError("cancelled")
        finally:
            self._state()
