"""Hearing: microphone audio -> voice activity -> recognizer -> what was heard.

The microphone hands audio to :meth:`Listener.hear` from its own thread (or, on the
simulated vest, from a tick hook). Voice activity is found at once (Silero is cheap);
each finished utterance is recognized in the listener's worker, never in a tick, and
``on_heard`` gets the text. The worker starts on an utterance before the robot's wait
for silence is over: on the detector's draft (the speech so far, after a short pause);
when the utterance ends with nothing said after the draft, the draft's text is the
utterance's and is told at once (a draft that fell short is forgotten; one that waited
while the worker was busy and was overtaken by newer speech is never recognized, and one
being recognized when speech goes on is stopped: a child who pauses often neither queues
up drafts nor keeps the worker busy with them when the sentence ends). A draft whose text
is a whole turn (``whole_turn``: one of the dialogs' phrases, and none goes on from it)
shortens the wait for silence (:meth:`~engine.speech.vad.SpeechDetector.whole_turn`).

While the robot speaks it keeps listening, and never answers its own voice: an echo
canceller (:mod:`engine.speech.echo_canceller`) takes what the speaker plays (known from
:class:`~engine.speech.speaker.SelfHearing`) out of the microphone's audio, and the
detector, while the robot speaks and just after, starts speech only on sound the robot's
voice cannot explain (:attr:`~engine.speech.vad.SpeechDetector.strict`). A person who
speaks over the robot is heard like anyone else, and told at once to
``on_barge_in(onset_s)`` (when their voice began, clock seconds), so the robot can stop
talking. A voice that begins while the robot is silent is told to ``on_voice(at_s)``, so
the robot starts no sentence over it.

Without a canceller the microphone is ignored while the robot speaks. Someone who speaks
over it is then not heard; what can be known of it is told to
``on_not_listened(from_s, until_s, why)``: here, speech already under way when the robot
stops (its start was lost); the simulated room knows who spoke when, and tells it itself
(:mod:`engine.robot_io.robot_speech`).
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from dataclasses import dataclass

from engine.clock import Clock
from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.speech.echo_canceller import FRAME, EchoCanceller
from engine.speech.recognizer import Recognizer
from engine.speech.settling import Settling
from engine.speech.speaker import SelfHearing
from engine.speech.vad import SpeechDetector, Utterance

log = logging.getLogger(__name__)
JOINS_WITHIN_S = 2 * FRAME / SPEECH_RATE_HZ
"""Spans of not listening this close (seconds) are one: two canceller frames (20 ms)."""
ALREADY_S = 0.15
"""Speech this soon after the robot fell silent was already under way while it spoke."""
NotListenedListener = Callable[[float, float, str], None]
"""Told ``(from_s, until_s, why)`` (clock seconds) of speech the robot did not listen to."""
BargeInListener = Callable[[float], None]
"""Told when a person's voice began over the robot's (clock seconds)."""
VoiceListener = Callable[[float], None]
"""Told when a person's voice began while the robot was silent (clock seconds: the end of
the microphone's piece in which it was found)."""


@dataclass(frozen=True)
class Heard:
    """One utterance heard: its text ("" when nothing intelligible), when the person
    stopped speaking and when the text was ready (clock seconds)."""

    text: str
    ended_s: float
    recognized_s: float


class Listener:
    """Cuts the microphone stream into utterances and recognizes each in a worker."""

    def __init__(
        self,
        detector: SpeechDetector,
        recognizer: Recognizer,
        clock: Clock,
        on_heard: Callable[[Heard], None],
        *,
        self_hearing: SelfHearing | None = None,
        settling: Settling | None = None,
        on_not_listened: NotListenedListener | None = None,
        whole_turn: Callable[[str], bool] | None = None,
        canceller: EchoCanceller | None = None,
        on_barge_in: BargeInListener | None = None,
        on_voice: VoiceListener | None = None,
    ) -> None:
        """``whole_turn(text)``: whether a draft's text is all a person means to say (None:
        the robot always waits ``detector.end_silence_s``); ``canceller``: the robot
        listens while it speaks (None: it is deaf then)."""
        self.detector = detector
        self.recognizer = recognizer
        self.clock = clock
        self.on_heard = on_heard
        self.self_hearing = self_hearing or SelfHearing()
        self.settling = settling or Settling()
        self._working = 0
        self._lock = threading.Lock()
        self._queue: queue.Queue[tuple[Utterance, float | None] | None] = queue.Queue()
        """Utterances to recognize with when they ended (None: a draft, not told)."""
        self._draft_text: str | None = None
        self._thread: threading.Thread | None = None
        self.ignored_s = 0.0
        """Seconds of microphone audio ignored because the robot was speaking."""
        self.on_not_listened = on_not_listened
        self.whole_turn = whole_turn
        self.canceller = canceller
        self.on_barge_in = on_barge_in
        self.on_voice = on_voice
        detector.on_pause = self._draft
        self._deaf_since_s: float | None = None
        self._held_back: list[tuple[Utterance, float | None]] | None = None
        self._deaf_spans: list[list[float]] = []
        self._listening_since_s: float | None = None

    def hear(self, audio: Audio, ends_at_s: float) -> None:
        """A piece of the microphone stream (16 kHz) that ended at ``ends_at_s``. What it
        finished (drafts, utterances) goes to the worker once the whole piece is taken, so
        which draft a later one overtook never depends on how fast the worker was."""
        self._held_back = []
        try:
            self._hear(audio, ends_at_s)
        finally:
            held, self._held_back = self._held_back, None
            for item in held:
                self._queue.put(item)
            if held and self._thread is None:
                self.start()

    def _hear(self, audio: Audio, ends_at_s: float) -> None:
        starts_at_s = ends_at_s - audio.seconds
        speaking = self.self_hearing.deaf_at(starts_at_s) or self.self_hearing.deaf_at(ends_at_s)
        if self.canceller is not None:
            self._hear_over_the_robot(audio, starts_at_s, ends_at_s, speaking)
            return
        if speaking:
            if self.detector.in_speech:
                self.detector.reset()  # what was being heard ran into the robot's voice
            self._not_listening(starts_at_s, ends_at_s)
            self.ignored_s += audio.seconds
            if self._deaf_since_s is None:
                self._deaf_since_s = starts_at_s
            self._listening_since_s = None
            return
        if self._deaf_since_s is not None:  # the robot stopped speaking: listening again
            self._listening_since_s, self._deaf_since_s = starts_at_s, None
        was_speech = self.detector.in_speech
        utterances = self.detector.feed(audio.samples)
        self._voice_began(was_speech, utterances, ends_at_s)
        self._already_speaking(ends_at_s)
        for utterance in utterances:
            late_s = (self.detector.position - utterance.end_sample) / audio.rate_hz
            self._submit(utterance, ends_at_s - late_s)

    def _hear_over_the_robot(
        self, audio: Audio, starts_at_s: float, ends_at_s: float, speaking: bool
    ) -> None:
        """A piece heard with the robot's own voice taken out; a voice that began over the
        robot's is told to ``on_barge_in``."""
        assert self.canceller is not None
        reference = self.self_hearing.reference(starts_at_s, len(audio.samples))
        samples, played = self.canceller.cancel(audio.samples, reference)
        ends_at_s -= self.canceller.lag_samples / audio.rate_hz  # still in the canceller
        self.detector.strict = speaking
        self.detector.echo_learned = self.canceller.learned
        self.detector.held = speaking and not (
            self.canceller.learned and self.detector.residual_echo.learned
        )
        if self.detector.held:  # nobody can be told from the robot yet: not listening
            self._not_listening(starts_at_s, ends_at_s)
        was_speech = self.detector.in_speech
        utterances = self.detector.feed(samples, played)
        if not speaking:
            self._voice_began(was_speech, utterances, ends_at_s)
        onset = self.detector.take_onset()
        if onset is not None and self.on_barge_in is not None:
            try:
                self.on_barge_in(ends_at_s - (self.detector.position - onset) / audio.rate_hz)
            except Exception:  # whoever listens must not stop the robot hearing
                log.exception("telling a person spoke over the robot failed")
        for utterance in utterances:
            late_s = (self.detector.position - utterance.end_sample) / audio.rate_hz
            self._submit(utterance, ends_at_s - late_s)

    def _voice_began(self, was_speech: bool, utterances: list[Utterance], at_s: float) -> None:
        """A voice that began in the piece ending at ``at_s`` while the robot was silent is
        told to ``on_voice``: the robot holds its tongue while a person talks. A person who
        goes on at once after a pause long enough to end what they said has begun anew."""
        in_speech, ended = self.detector.in_speech, bool(utterances)
        began = not was_speech and (in_speech or ended)
        went_on = was_speech and ended and in_speech
        if not (began or went_on) or self.on_voice is None:
            return
        try:
            self.on_voice(at_s)
        except Exception:  # whoever listens must not stop the robot hearing
            log.exception("telling a person began to speak failed")

    def _not_listening(self, from_s: float, until_s: float) -> None:
        """It does not listen from ``from_s`` to ``until_s`` (clock seconds). Pieces in a
        row are one span: a piece ends less than a canceller's frame early (what waits in
        it), and those gaps split a deafness into pieces that fell out of the last 16."""
        with self._lock:
            if self._deaf_spans and self._deaf_spans[-1][1] >= from_s - JOINS_WITHIN_S:
                self._deaf_spans[-1][1] = until_s
            else:
                self._deaf_spans = [*self._deaf_spans[-15:], [from_s, until_s]]

    def deaf_at(self, at_s: float) -> bool:
        """Whether it was not listening at ``at_s`` (the robot was speaking and it could
        not tell a person from the robot's voice)."""
        with self._lock:
            return any(start <= at_s < end for start, end in self._deaf_spans)

    def _already_speaking(self, now_s: float) -> None:
        """Speech found within :data:`ALREADY_S` of the robot falling silent began while
        it spoke: its start was not heard (told once)."""
        since = self._listening_since_s
        if since is None or self.on_not_listened is None:
            return
        if self.detector.in_speech:
            self._listening_since_s = None
            try:
                self.on_not_listened(
                    since,
                    since,
                    "someone was already speaking when the robot stopped speaking; the "
                    "start of it was not heard",
                )
            except Exception:  # whoever listens must not stop the robot hearing
                log.exception("telling what was not listened to failed")
        elif now_s - since > ALREADY_S:
            self._listening_since_s = None

    def settled(self) -> bool:
        """No utterance waits for recognition."""
        return self._working == 0

    def _draft(self, utterance: Utterance) -> None:
        """The speech so far, recognized while the robot waits to be sure it ended."""
        self._submit(utterance, None)

    def _submit(self, utterance: Utterance, ended_s: float | None) -> None:
        with self._lock:
            self._working += 1
        if self._held_back is not None:  # within a piece: sent when it is all taken
            self._held_back.append((utterance, ended_s))
            return
        self._queue.put((utterance, ended_s))
        if self._thread is None:
            self.start()

    def start(self) -> None:
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="listener", daemon=True)
            self._thread.start()

    def close(self) -> None:
        if self._thread is not None:
            self._queue.put(None)
            self._thread.join(timeout=10.0)
            self._thread = None

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            utterance, ended_s = item
            if ended_s is None and not self._queue.empty():  # overtaken: a newer one waits
                self._draft_text = None
                with self._lock:
                    self._working -= 1
                continue
            drafted = self._draft_text if utterance.drafted else None
            self._draft_text = None
            text = drafted if drafted is not None else self._recognized(utterance, ended_s is None)
            try:
                if ended_s is None:
                    self._draft_text = text
                    if text and self.whole_turn is not None and self.whole_turn(text):
                        self.detector.whole_turn(utterance)
                else:
                    self.on_heard(Heard(text, ended_s, self.clock.now()))
            except Exception:  # whoever listens must not stop the robot hearing
                log.exception("handling what was heard failed")
            finally:
                with self._lock:
                    self._working -= 1
                self.settling.changed()

    def _recognized(self, utterance: Utterance, draft: bool) -> str:
        """Its text; a draft's recognition stops as soon as speech goes on after it (its
        text would never be wanted, and the worker is wanted for what comes next)."""

        def overtaken() -> bool:
            return self.detector.overtaken(utterance)

        try:
            return self.recognizer.transcribe(
                utterance.audio, abandon=overtaken if draft else None
            ).text
        except Exception as error:  # a model that failed on this audio
            log.warning("recognition failed: %s", error)
            return ""
