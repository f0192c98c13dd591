"""``vest hear HEARD.wav --echo-of PLAYED.wav``: how a robot hears its own voice.

Record the robot's microphone while its speaker plays a sentence (the hardware guide says
how). This measures the path from speaker to microphone (delay, loudness, the room's
reverberation), prints it as a scenario's ``echo:`` event, so the simulated vest meets the
same room, and runs the robot's listening (the echo canceller, the residual-echo check
while it speaks) over the recording: a robot that would stop for its own voice here is
told so.
"""

from __future__ import annotations

import json

import numpy as np

from engine.clock import VirtualClock
from engine.errors import ConfigError, DeviceError
from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.sim.echo_path import EchoPath
from engine.speech.echo_canceller import EchoCanceller, NoEchoCancellerError
from engine.speech.listener import Listener
from engine.speech.recognizers import NoWords
from engine.speech.speaker import SelfHearing
from engine.speech.vad import SileroVad, speech_detector

PIECE = 1024
"""Samples the robot's microphone hands over at a time (64 ms)."""


def hear_own_voice(
    heard: Audio, played: Audio, heard_name: str, played_name: str, *, as_json: bool
) -> int:
    """Print the echo path of ``heard`` (the microphone) of ``played`` (the speaker) and
    how often the robot would have stopped for its own voice; 0 when it never would, 1
    when it would (ConfigError when the recording holds nothing of what was played)."""
    microphone = heard.resampled(SPEECH_RATE_HZ).samples
    speaker = played.resampled(SPEECH_RATE_HZ).samples
    if not np.any(speaker):
        raise ConfigError(f"{played_name}: silent: play a sentence of the robot's")
    try:
        path = EchoPath.measured(speaker, microphone)
    except ValueError as error:
        raise ConfigError(f"{heard_name}: {error}") from None
    try:
        EchoCanceller()
    except NoEchoCancellerError as error:
        raise DeviceError(str(error)) from None
    stopped = _stops_for_itself(microphone, speaker)
    event = {
        "delay_s": round(path.delay_s, 3),
        "gain_db": round(path.gain_db, 1),
        "rt60_s": round(path.rt60_s, 2),
    }
    if as_json:
        print(json.dumps({"file": heard_name, "echo": event, "stopped_itself": stopped}))
    else:
        print(
            f"{heard_name}: the robot's voice reaches its microphone after "
            f"{path.delay_s * 1000:.0f} ms at {path.gain_db:+.1f} dB; the room rings for "
            f"{path.rt60_s:.2f} s (rt60)"
        )
        shown = ", ".join(f"{name}: {value:g}" for name, value in event.items())
        print(f"  in a scenario: - {{at: 0, echo: {{{shown}}}}}")
        times = ", ".join(f"{at_s:.2f} s" for at_s in stopped)
        print(
            f"  it would stop for its own voice {len(stopped)} time(s), at {times}"
            if stopped
            else "  it would never stop for its own voice here"
        )
    return 1 if stopped else 0


def _stops_for_itself(microphone: np.ndarray, speaker: np.ndarray) -> list[float]:
    """When (seconds into the recording) a voice would have begun over the robot's: the
    robot's listening over the recording twice, the first time only to teach its canceller
    the room (on a robot the canceller has learned the room before)."""
    clock, hearing, canceller = VirtualClock(), SelfHearing(), EchoCanceller()
    stopped: list[float] = []
    length = len(microphone)
    second_s = length / SPEECH_RATE_HZ
    for start_s in (0.0, second_s):
        hearing.played(Audio(speaker, SPEECH_RATE_HZ), start_s)
        hearing.speaking(start_s, start_s + len(speaker) / SPEECH_RATE_HZ)
    listener = Listener(
        speech_detector(SileroVad()),
        NoWords(),
        clock,
        lambda heard: None,
        self_hearing=hearing,
        canceller=canceller,
        on_barge_in=lambda onset_s: stopped.append(onset_s - second_s),
    )
    for start_s in (0.0, second_s):
        for end in range(PIECE, length + 1, PIECE):
            clock.advance(PIECE / SPEECH_RATE_HZ)
            piece = Audio(microphone[end - PIECE : end], SPEECH_RATE_HZ)
            listener.hear(piece, start_s + end / SPEECH_RATE_HZ)
    listener.close()
    return [at_s for at_s in stopped if at_s >= 0]
