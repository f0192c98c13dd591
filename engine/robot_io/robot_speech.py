"""The robot's speech, assembled: voice and speaker, microphone and listener.

On the simulated vest the microphone and speaker are the simulated room's; on a robot
they are the ALSA devices its config names. A device or model that is missing is named
in ``problems`` and the rest runs: without a microphone the robot does not hear, and
without a speaker its answers fail with the reason.
"""

from __future__ import annotations

import logging
import os
import threading
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import SPEECH_HEARD, SPEECH_NOT_LISTENED
from engine.clock import Clock
from engine.errors import ConfigError
from engine.files.yaml_values import plain
from engine.hardware.config import AudioConfig
from engine.loader.substitution import Profile
from engine.media.audio import Audio, read_wav, with_noise, write_wav
from engine.media.audio_devices import AlsaMicrophone, AlsaSpeaker, AudioDeviceError
from engine.sim.room import RoomSpeaker, SimulatedRoom
from engine.speech.listener import Heard, Listener, NotListenedListener
from engine.speech.phrase_search import PhraseGrammar
from engine.speech.recognizer import RecognizerError
from engine.speech.recognizers import default_recognizer
from engine.speech.settings import SPEECH_PROFILE_PARAMS
from engine.speech.settling import Settling
from engine.speech.speaker import Playback, SelfHearing, Speaker, Utterance
from engine.speech.vad import SileroVad, speech_detector
from engine.speech.voice_models import default_voice
from engine.speech.voices import EspeakVoice, Voice, steady_voice

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


class NoPlayback:
    """A speaker that is not there: every utterance fails with why."""

    def __init__(self, why: str) -> None:
        self.why = why

    def start(self, audio: Audio, at_s: float) -> None:
        raise AudioDeviceError(self.why)

    def stop(self) -> None:
        """Nothing plays."""


class BothPlaybacks:
    """The simulated room (which the microphone hears) and a real speaker (for people)."""

    def __init__(self, *parts: Playback) -> None:
        self.parts = parts

    def start(self, audio: Audio, at_s: float) -> None:
        for part in self.parts:
            part.start(audio, at_s)

    def stop(self) -> None:
        for part in self.parts:
            part.stop()


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
    self_hearing: SelfHearing = field(default_factory=SelfHearing)
    blackboard: Blackboard | None = None
    on_not_listened: NotListenedListener | None = None
    _spoken_in_room: list[tuple[float, float]] = field(default_factory=list)
    """When each person in the simulated room spoke (clock seconds), until it is checked
    against when the robot was not listening."""
    _lines: list[tuple[float, float]] = field(default_factory=list)
    """When each scripted line is spoken in the simulated room (clock seconds)."""
    _due: list[tuple[float, str]] = field(default_factory=list)
    """On a virtual clock: what was heard, and when it is staged."""
    _due_lock: threading.Lock = field(default_factory=threading.Lock)

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
        for _, text in sorted(due):
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
            deaf = [
                from_s + index * DEAF_STEP_S
                for index in range(steps)
                if self.self_hearing.deaf_at(from_s + index * DEAF_STEP_S)
            ]
            if len(deaf) * DEAF_STEP_S >= NOT_LISTENED_AT_LEAST_S and self.on_not_listened:
                missed = len(deaf) * DEAF_STEP_S
                self.on_not_listened(
                    deaf[0],
                    deaf[-1] + DEAF_STEP_S,
                    f"someone spoke while the robot was speaking ({missed:.1f} s of "
                    f"{until_s - from_s:.1f} s); it does not listen while it speaks",
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
                self._due.append((due_s, heard.text))

        def not_listened(from_s: float, until_s: float, why: str) -> None:
            blackboard.stage_event(
                SPEECH_NOT_LISTENED, {"from_s": from_s, "until_s": until_s, "why": why}
            )

        self.on_not_listened = not_listened  # the simulated room tells what it knows
        if self.listener is not None:
            self.listener.on_heard = stage
            if self.room is None:  # a real microphone: what the listener can tell
                self.listener.on_not_listened = not_listened

    def world_changed(self, world: object, what: str) -> None:
        """Nothing the room carries changes with the polled senses."""

    def world_event(self, kind: str, value: Any) -> None:
        """A scenario's ``hear:`` is said in the room, now."""
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


def build_speech(
    audio: AudioConfig,
    clock: Clock,
    *,
    on_heard: Callable[[Heard], None] = lambda heard: None,
    simulated: bool,
    phrases: Iterable[str],
    settle: bool,
    speed: float = 1.0,
    volume: float = 1.0,
    voice_name: str | None = None,
    recognizer_name: str | None = None,
    children: bool = False,
    on_utterance: Callable[[Utterance], None] | None = None,
) -> RobotSpeech:
    """The speech of a robot with ``audio`` devices (on the simulated vest's room when
    ``simulated``), listening for ``phrases``; ``children``: it hears children
    (:func:`~engine.speech.vad.speech_detector`, :mod:`engine.speech.children`).
    ``settle``: the clock is virtual."""
    problems: dict[str, str] = {}
    settling = Settling()
    self_hearing = SelfHearing()
    voice, why = default_voice(voice_name)
    if why:
        problems["voice"] = why
    if settle:
        voice = steady_voice(voice)  # a virtual clock's run is the same every time
    room = SimulatedRoom(clock) if simulated else None
    playback: Playback
    if audio.speaker is not None:
        card = AlsaSpeaker(audio.speaker)
        try:
            card.open(voice.synthesize("a").rate_hz)
            playback = card if room is None else BothPlaybacks(RoomSpeaker(room), card)
        except AudioDeviceError as error:  # said at start-up; each answer tries it again
            problems["speaker"] = str(error)
            playback = RoomSpeaker(room) if room is not None else card
    elif room is not None:
        playback = RoomSpeaker(room)
    else:
        playback = NoPlayback("the robot config names no speaker (audio: speaker:)")
    speaker = Speaker(
        voice,
        playback,
        clock,
        fallback_voice=EspeakVoice() if voice.name != "espeak" else None,
        self_hearing=self_hearing,
        speed=speed,
        volume=volume,
        on_utterance=on_utterance,
        settling=settling,
        instant_synthesis=settle,
    )
    listener: Listener | None = None
    try:
        recognizer, instead = default_recognizer(recognizer_name, children=children)
        if instead:
            problems["recognizer"] = instead
        listened = list(phrases)
        recognizer.listen_for(listened)
        listener = Listener(
            speech_detector(SileroVad(), children=children),
            recognizer,
            clock,
            on_heard,
            self_hearing=self_hearing,
            settling=settling,
            whole_turn=PhraseGrammar(listened).is_a_whole_turn,
        )
    except (RecognizerError, ImportError) as error:
        problems["recognizer"] = str(error)
    speech = RobotSpeech(
        speaker, listener, room, settling, settle, voice, problems, self_hearing=self_hearing
    )
    for part in (playback, *getattr(playback, "parts", ())):
        if isinstance(part, AlsaSpeaker):
            speech.closers.append(part.close)
    if room is None and audio.microphone is not None and listener is not None:
        heard_by = listener
        microphone = AlsaMicrophone(audio.microphone, lambda a: heard_by.hear(a, clock.now()))
        try:
            microphone.start()
            speech.microphone = microphone
        except AudioDeviceError as error:
            problems["microphone"] = str(error)
    return speech


def audio_folder(folder: Path) -> Callable[[Utterance], None]:
    """Keeps each utterance as ``NNN-robot.wav`` in ``folder`` (made if missing), its
    owner's alone (a sentence may quote what a person said: never in a file's name);
    ConfigError when it cannot be made."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError as error:
        raise ConfigError(
            f"--audio-out {folder}: cannot make it ({error.strerror or error})"
        ) from None
    count = [0]

    def keep(utterance: Utterance) -> None:
        count[0] += 1
        path = folder / f"{count[0]:03d}-robot.wav"
        try:
            os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600))
            path.chmod(0o600)  # one of an earlier run, made with another mode
            write_wav(path, utterance.audio)
        except OSError as error:
            log.warning("could not write %s: %s", path, error)

    return keep


def speech_settings(profile: Profile | None) -> dict[str, Any]:
    """The voice, speed, recognizer and hearing a profile asks for, as :func:`build_speech`
    keywords."""
    if profile is None:
        return {}
    values = {
        name: plain(profile.params[name].value)
        for name in SPEECH_PROFILE_PARAMS
        if name in profile.params
    }
    settings: dict[str, Any] = {}
    if "voice" in values:
        settings["voice_name"] = str(values["voice"])
    if "speech_rate" in values:
        settings["speed"] = float(values["speech_rate"])
    if "recognizer" in values:
        settings["recognizer_name"] = str(values["recognizer"])
    if "hearing" in values:
        settings["children"] = values["hearing"] == "children"
    return settings
