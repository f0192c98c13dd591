"""The robot's speech at work: what it hears staged on the blackboard, a person who speaks
over it stopping it (barge-in), and on the simulated vest the room it speaks and hears in.

:mod:`engine.robot_io.speech_assembly` puts the parts together. A person's voice that
begins while the robot speaks (the listener's ``on_barge_in``) silences the speaker at
once, if what it says may be interrupted; the scheduler's hook then tells the robot
(``on_interrupted``), which halts the tree that was speaking and gives the speaker's turn
to the person (:class:`PersonsTurn`) until what they said is heard.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import SPEECH_HEARD, SPEECH_NOT_LISTENED
from engine.media.audio import Audio, read_wav, with_noise
from engine.media.audio_devices import AlsaMicrophone
from engine.services.jobs import Job
from engine.sim.echo_path import EchoPath
from engine.sim.room import RoomSpeaker, SimulatedRoom
from engine.speech.listener import Heard, Listener, NotListenedListener
from engine.speech.settling import Settling
from engine.speech.speaker import Speaker
from engine.speech.voices import Voice, steady_voice

log = logging.getLogger(__name__)
HEARD_KEPT = 100
LEAD_S = 0.3
"""Quiet before a person's scripted utterance starts (noise is mixed over it too)."""
HEARD_AFTER_LINE_S = 0.4
"""On a virtual clock, a scripted line is heard this long after its recording ends: the
VAD's 0.3 s of silence, and 0.1 s (three of its 32 ms frames) to spare. See
:meth:`RobotSpeech.heard_when`."""
DEAF_STEP_S = 0.05
NOT_LISTENED_AT_LEAST_S = 0.2
"""A person's speech that overlaps the robot's by less is not told as not listened to
(the robot's last syllable over the first of an answer)."""
STOPS_AFTER_S = 0.5
"""On a virtual clock, the robot stops talking this long after a scripted line spoken over
it starts (its lead of quiet excluded): the listener finds the voice 0.1 to 0.4 s in, and
where the sound stops must not depend on a frame more or less on another machine
(:meth:`RobotSpeech.snapped`; bench/bench_barge_in.py measures the real stop latency)."""
FLOOR_AT_MOST_S = 10.0
"""A person who spoke over the robot has the speaker's turn until what they said is heard,
and at most this long (seconds)."""
PersonSpeaks = Callable[[float, Job], None]
"""Told ``(onset_s, floor)`` on the scheduler's thread: a person began to speak at
``onset_s`` while the robot was silent; ``floor`` is done when what they said is heard."""
Interrupted = Callable[[float, str, bool, Job], None]
"""Told ``(onset_s, saying, heard_last, floor)`` on the scheduler's thread: a person's
voice began at ``onset_s`` (clock seconds) over the robot saying ``saying``, which stopped;
``heard_last``: its last sentence had begun by then (a question ending it was put);
``floor`` is done when the person's turn is over (what they said was heard)."""


class PersonsTurn:
    """The turn of a person who spoke over the robot (a job, so that trees wait for it as
    for each other): over once their utterance ended and was recognized, or after
    :data:`FLOOR_AT_MOST_S`; on a virtual clock, when a scripted line is heard
    (:meth:`RobotSpeech.heard_when`), so it ends at the same tick on every machine."""

    def __init__(self, speech: RobotSpeech, onset_s: float) -> None:
        self.speech = speech
        self.clock = speech.speaker.clock
        self.until_s = onset_s + FLOOR_AT_MOST_S
        self.heard_s = speech.heard_after(onset_s) if speech.settle else None
        self.cancelled = False

    def done(self) -> bool:
        now_s = self.clock.now()
        if self.cancelled or now_s >= self.until_s:
            return True
        if self.heard_s is not None:
            return now_s >= self.heard_s - 1e-9
        listener = self.speech.listener
        return listener is None or (not listener.detector.in_speech and listener.settled())

    def error(self) -> BaseException | None:
        return None

    def result(self) -> Any:
        return None

    def cancel(self) -> None:
        self.cancelled = True


@dataclass
class RobotSpeech:
    """The assembled speech parts and what could not be started."""

    speaker: Speaker
    listener: Listener | None
    room: SimulatedRoom | None
    settling: Settling
    settle: bool
    voice: Voice
    problems: dict[str, str] = field(default_factory=dict)
    microphone: AlsaMicrophone | None = None
    closers: list[Callable[[], None]] = field(default_factory=list)
    _spoken: dict[str, Audio] = field(default_factory=dict)
    heard: deque[Heard] = field(default_factory=lambda: deque(maxlen=HEARD_KEPT))
    """The last utterances heard (text and times), for whoever inspects the robot."""
    blackboard: Blackboard | None = None
    on_not_listened: NotListenedListener | None = None
    _spoken_in_room: list[tuple[float, float]] = field(default_factory=list)
    """When each person in the simulated room spoke (clock seconds), until it is checked
    against when the robot was not listening."""
    _lines: list[tuple[float, float]] = field(default_factory=list)
    """When each scripted line is spoken in the simulated room (clock seconds)."""
    _due: list[tuple[float, float, str]] = field(default_factory=list)
    """On a virtual clock: when it is staged, when it ended, and what was heard."""
    _due_lock: threading.Lock = field(default_factory=threading.Lock)
    room_speaker: RoomSpeaker | None = None
    on_interrupted: Interrupted | None = None
    """Told each time a person stopped the robot talking (the robot halts the tree)."""
    on_person_speaks: PersonSpeaks | None = None
    """Told each time a person began to speak while the robot was silent."""
    _voices: list[tuple[float, float]] = field(default_factory=list)
    """(when it is told, when the voice began) of voices begun while the robot was silent."""
    _barge_ins: list[tuple[float, float]] = field(default_factory=list)
    """On a virtual clock: (when the robot stops talking, when the voice began)."""
    _stopped: list[tuple[float, str, bool]] = field(default_factory=list)
    """(when the voice began, what the robot was saying, whether its last sentence had
    begun), until the scheduler's hook."""

    def describe(self) -> str:
        """Which voice speaks and which recognizer hears, in words (told at start-up)."""
        hears = (
            f"hears with {getattr(self.listener.recognizer, 'name', 'its recognizer')}"
            if self.listener is not None
            else "does not hear"
        )
        return f"the {self.voice.name} voice; {hears}"

    def __call__(self, now_s: float) -> None:
        """A tick hook: the simulated microphone hears the room up to now; on a virtual
        clock, first let the speaker place what it was asked to say (the microphone must
        know when the robot speaks), then wait for recognition, so time cannot race them."""
        if self.settle:
            self.settling.wait(self.settled)
        if self.room is not None and self.listener is not None:
            self.listener.hear(self.room.capture(now_s), now_s)
            self._not_listened_in_room(now_s)
        if self.settle:
            self.settling.wait(self.settled)
            self._stage_due(now_s)
            self._stop_when_due(now_s)
        with self._due_lock:
            stopped, self._stopped = self._stopped, []
            voices = [item for item in self._voices if item[0] <= now_s + 1e-9]
            self._voices = [item for item in self._voices if item[0] > now_s + 1e-9]
        for onset_s, saying, heard_last in stopped:
            if self.on_interrupted is not None:
                self.on_interrupted(onset_s, saying, heard_last, PersonsTurn(self, onset_s))
        for _, onset_s in sorted(voices):
            if self.on_person_speaks is not None:
                self.on_person_speaks(onset_s, PersonsTurn(self, onset_s))

    def voice_began(self, at_s: float) -> None:
        """A person began to speak while the robot was silent (the listener's thread): told
        at the next tick (on a virtual clock: as :meth:`snapped` says, on every machine
        alike)."""
        with self._due_lock:
            self._voices.append(self.snapped(at_s) if self.settle else (at_s, at_s))

    def barged_in(self, onset_s: float) -> None:
        """A person's voice began at ``onset_s`` over the robot's (the listener's thread):
        the robot stops talking now (on a virtual clock: as :meth:`snapped` says)."""
        if not self.settle:
            self._hush(onset_s)
            return
        with self._due_lock:
            self._barge_ins.append(self.snapped(onset_s))

    def _line_of(self, onset_s: float) -> tuple[float, float] | None:
        """The scripted line (start, end: clock seconds) a voice found at ``onset_s`` is."""
        for start_s, end_s in self._lines:
            if start_s - HEARD_AFTER_LINE_S <= onset_s <= end_s:
                return start_s, end_s
        return None

    def heard_after(self, onset_s: float) -> float | None:
        """On a virtual clock, when the scripted line a voice that began at ``onset_s``
        belongs to is heard (None: it is no scripted line's)."""
        line = self._line_of(onset_s)
        return line[1] + HEARD_AFTER_LINE_S if line is not None else None

    def snapped(self, onset_s: float) -> tuple[float, float]:
        """On a virtual clock, (when the robot stops, when the voice began) for a voice the
        VAD found to begin at ``onset_s``: :data:`STOPS_AFTER_S` into the scripted line it
        belongs to, which began at the line's start (the same on every machine), or at
        once for a voice that is no scripted line's."""
        line = self._line_of(onset_s)
        return (line[0] + STOPS_AFTER_S, line[0]) if line is not None else (onset_s, onset_s)

    def _stop_when_due(self, now_s: float) -> None:
        with self._due_lock:
            due = [item for item in self._barge_ins if item[0] <= now_s + 1e-9]
            self._barge_ins = [item for item in self._barge_ins if item[0] > now_s + 1e-9]
        for _, onset_s in sorted(due):
            self._hush(onset_s)
            self.settling.wait(self.settled)

    def _hush(self, onset_s: float) -> None:
        hushed = self.speaker.hush()
        if hushed is not None:
            began = hushed.last_sentence_s
            with self._due_lock:
                self._stopped.append((onset_s, hushed.text, began is not None and began <= onset_s))

    def heard_when(self, ended_s: float) -> float | None:
        """On a virtual clock, when an utterance whose end the VAD found at ``ended_s``
        (clock seconds) is heard: the end of the scripted line it belongs to plus
        :data:`HEARD_AFTER_LINE_S`. The VAD finds the end of speech by its model's floating
        point, which differs a little from one CPU to another: a frame later, and the line
        would be heard a tick later on one machine than on another. Snapped to the line's
        end (known from its recording), the timeline is the same on every machine as long
        as the VAD finds the end within 0.1 s of where it does here. None: the utterance
        is no scripted line's (heard at once)."""
        for start_s, end_s in self._lines:
            if start_s <= ended_s <= end_s + HEARD_AFTER_LINE_S:
                return end_s + HEARD_AFTER_LINE_S
        return None

    def _stage_due(self, now_s: float) -> None:
        with self._due_lock:
            due = [item for item in self._due if item[0] <= now_s + 1e-9]
            self._due = [item for item in self._due if item[0] > now_s + 1e-9]
        for _, _, text in sorted(due):  # the parts of one line in the order they were said
            if self.blackboard is not None:
                self.blackboard.stage_event(SPEECH_HEARD, text)

    def _not_listened_in_room(self, now_s: float) -> None:
        """The simulated room knows who spoke when: each person's speech that ended by
        ``now_s`` and fell, for :data:`NOT_LISTENED_AT_LEAST_S` or more, into a time the
        robot was speaking (and so not listening) is told to ``on_not_listened``."""
        ended = [span for span in self._spoken_in_room if span[1] <= now_s]
        if not ended:
            return
        self._spoken_in_room = [span for span in self._spoken_in_room if span[1] > now_s]
        for from_s, until_s in ended:
            steps = max(1, round((until_s - from_s) / DEAF_STEP_S))
            times = [from_s + index * DEAF_STEP_S for index in range(steps)]
            deaf = [at_s for at_s in times if self.listener and self.listener.deaf_at(at_s)]
            if len(deaf) * DEAF_STEP_S >= NOT_LISTENED_AT_LEAST_S and self.on_not_listened:
                missed = len(deaf) * DEAF_STEP_S
                why = (
                    "it does not listen while it speaks"
                    if self.listener is None or self.listener.canceller is None
                    else "it could not yet tell a voice from its own (it learns the room "
                    "in its first seconds of speech)"
                )
                self.on_not_listened(
                    deaf[0],
                    deaf[-1] + DEAF_STEP_S,
                    f"someone spoke while the robot was speaking ({missed:.1f} s of "
                    f"{until_s - from_s:.1f} s); {why}",
                )

    def settled(self) -> bool:
        listener = self.listener
        return self.speaker.settled() and (listener is None or listener.settled())

    def person_says(
        self, text: str | None, wav: str | None, snr_db: float | None, at_s: float
    ) -> None:
        """A person in the simulated room says ``text`` (in the robot's voice, the only
        one installed) or plays ``wav``, with noise ``snr_db`` below it."""
        if self.room is None:
            return
        if wav is not None:
            spoken = read_wav(Path(wav))
        else:
            spoken = self._spoken.get(text or "") or self.prepare(text or "")
        audio = (
            Audio.silence(LEAD_S, spoken.rate_hz)
            .then(spoken)
            .then(Audio.silence(LEAD_S, spoken.rate_hz))
        )
        if snr_db is not None:
            audio = with_noise(audio, snr_db, seed=round(at_s * 1000))
        self.room.add(audio.scaled(0.5), at_s)
        line = (at_s + LEAD_S, at_s + LEAD_S + spoken.seconds)
        self._spoken_in_room.append(line)
        self._lines.append(line)

    def prepare(self, text: str) -> Audio:
        """Synthesize what a person will say before it is said (a scenario's lines)."""
        voice = steady_voice(self.voice)
        spoken = self._spoken[text] = voice.synthesize(text)
        return spoken

    def hears_into(self, blackboard: Blackboard) -> None:
        """What the robot hears is staged on ``blackboard`` as a ``/speech/heard`` event."""

        self.blackboard = blackboard

        def stage(heard: Heard) -> None:
            self.heard.append(heard)
            if not heard.text:
                return
            due_s = self.heard_when(heard.ended_s) if self.settle else None
            if due_s is None:
                blackboard.stage_event(SPEECH_HEARD, heard.text)
                return
            with self._due_lock:  # staged by the tick hook at its time
                self._due.append((due_s, heard.ended_s, heard.text))

        def not_listened(from_s: float, until_s: float, why: str) -> None:
            blackboard.stage_event(
                SPEECH_NOT_LISTENED, {"from_s": from_s, "until_s": until_s, "why": why}
            )

        self.on_not_listened = not_listened  # the simulated room tells what it knows
        if self.listener is not None:
            self.listener.on_heard = stage
            self.listener.on_barge_in = self.barged_in
            self.listener.on_voice = self.voice_began
            if self.room is None:  # a real microphone: what the listener can tell
                self.listener.on_not_listened = not_listened

    def world_changed(self, world: object, what: str) -> None:
        """Nothing the room carries changes with the polled senses."""

    def world_event(self, kind: str, value: Any) -> None:
        """A scenario's ``hear:`` is said in the room, now; its ``echo:`` changes how the
        microphone hears the robot."""
        if kind == "echo" and self.room_speaker is not None:
            self.room_speaker.echo = EchoPath(**value)
        if kind == "hear":
            said: dict[str, Any] = value if isinstance(value, dict) else {"text": str(value)}
            now_s = self.speaker.clock.now()
            self.person_says(said.get("text"), said.get("wav"), said.get("snr_db"), now_s)

    def close(self) -> None:
        self.speaker.close()
        if self.microphone is not None:
            self.microphone.close()
        if self.listener is not None:
            self.listener.close()
        for close in self.closers:
            close()
