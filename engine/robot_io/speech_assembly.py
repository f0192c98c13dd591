"""The robot's speech put together: voice and speaker, microphone, listener and echo
canceller, from the robot config's audio devices (or the simulated room), and the profile's
speech settings.

A device or model that is missing is named in ``problems`` and the rest runs: without a
microphone the robot does not hear, without a speaker its answers fail with the reason,
and without an echo canceller it does not listen while it speaks.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from engine.clock import Clock
from engine.errors import ConfigError
from engine.files.yaml_values import plain
from engine.hardware.config import AudioConfig
from engine.loader.substitution import Profile
from engine.media.audio import Audio, write_wav
from engine.media.audio_devices import AlsaMicrophone, AlsaSpeaker, AudioDeviceError
from engine.robot_io.robot_speech import RobotSpeech
from engine.sim.room import RoomSpeaker, SimulatedRoom
from engine.speech.echo_canceller import EchoCanceller, NoEchoCancellerError
from engine.speech.listener import Heard, Listener
from engine.speech.phrase_search import PhraseGrammar
from engine.speech.recognizer import RecognizerError
from engine.speech.recognizers import default_recognizer
from engine.speech.settings import SPEECH_PROFILE_PARAMS
from engine.speech.settling import Settling
from engine.speech.speaker import Playback, SelfHearing, Speaker, Utterance
from engine.speech.vad import SileroVad, speech_detector
from engine.speech.voice_models import default_voice
from engine.speech.voices import EspeakVoice, steady_voice

log = logging.getLogger(__name__)


class NoPlayback:
    """A speaker that is not there: every utterance fails with why."""

    def __init__(self, why: str) -> None:
        self.why = why

    def start(self, audio: Audio, at_s: float) -> None:
        raise AudioDeviceError(self.why)

    def stop(self, at_s: float) -> None:
        """Nothing plays."""


class BothPlaybacks:
    """The simulated room (which the microphone hears) and a real speaker (for people)."""

    def __init__(self, *parts: Playback) -> None:
        self.parts = parts

    def start(self, audio: Audio, at_s: float) -> None:
        for part in self.parts:
            part.start(audio, at_s)

    def stop(self, at_s: float) -> None:
        for part in self.parts:
            part.stop(at_s)


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
    room_speaker = RoomSpeaker(room) if room is not None else None
    playback: Playback
    if audio.speaker is not None:
        card = AlsaSpeaker(audio.speaker)
        try:
            card.open(voice.synthesize("a").rate_hz)
            playback = card if room_speaker is None else BothPlaybacks(room_speaker, card)
        except AudioDeviceError as error:  # said at start-up; each answer tries it again
            problems["speaker"] = str(error)
            playback = room_speaker or card
    elif room_speaker is not None:
        playback = room_speaker
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
        canceller: EchoCanceller | None = None
        try:
            canceller = EchoCanceller()
        except NoEchoCancellerError as error:  # it hears, but not while it speaks
            problems["echo canceller"] = str(error)
        listener = Listener(
            speech_detector(SileroVad(), children=children),
            recognizer,
            clock,
            on_heard,
            self_hearing=self_hearing,
            settling=settling,
            whole_turn=PhraseGrammar(listened).is_a_whole_turn,
            canceller=canceller,
        )
    except (RecognizerError, ImportError) as error:
        problems["recognizer"] = str(error)
    speech = RobotSpeech(
        speaker,
        listener,
        room,
        settling,
        settle,
        voice,
        problems,
        room_speaker=room_speaker,
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
