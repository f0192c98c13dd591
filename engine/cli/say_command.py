"""Speak with the robot's voice: on the speaker, or into a WAV file with -o.

The voice and speed are a profile's (--profile child), or --voice (hibari, the default; joe;
or espeak) and --rate (1 is the voice's natural speed). Sentences are synthesized one
by one; the first plays while the next is made.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from engine.cli.run_inputs import resolve_profile
from engine.clock import RealClock
from engine.errors import ConfigError, ServiceError, UsageError
from engine.loader.substitution import load_profile
from engine.media.audio import Audio, write_wav
from engine.robot_io.speech_assembly import speech_settings
from engine.speech.settings import VOICE_NAMES
from engine.speech.speaker import Speaker
from engine.speech.voice_models import DEFAULT_VOICE, load_voice
from engine.speech.voices import EspeakVoice, sentences

MAX_TEXT_CHARS = 5000


def _rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not 0.5 <= value <= 2.0:
        raise argparse.ArgumentTypeError(f"must be 0.5..2 (1 is natural), got {text}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("text", help="what to say")
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        metavar="OUT.wav",
        help="write a WAV file instead of playing",
    )
    parser.add_argument(
        "--profile",
        default=None,
        help="a profile (name in trees/profiles/ or path): its voice and speech_rate",
    )
    parser.add_argument(
        "--voice",
        choices=VOICE_NAMES,
        default=None,
        help=f"default: the profile's, or {DEFAULT_VOICE}",
    )
    parser.add_argument(
        "--rate", type=_rate, default=None, help="speed, 0.5..2 (default: the profile's, or 1)"
    )
    parser.add_argument(
        "--device", default=None, help="ALSA playback device (default: the config's)"
    )
    parser.add_argument(
        "--hardware",
        type=Path,
        default=None,
        metavar="CONFIG",
        help="robot config naming the speaker",
    )


def main(args: argparse.Namespace) -> int:
    text = args.text.strip()
    if not any(c.isalnum() for c in text):
        raise UsageError("nothing to say: the text has no letters or digits")
    if len(text) > MAX_TEXT_CHARS:
        raise UsageError(f"the text has {len(text)} characters; at most {MAX_TEXT_CHARS}")
    settings: dict[str, Any] = {}
    if args.profile is not None:
        path = resolve_profile(args.profile, [Path("trees")])
        settings = speech_settings(load_profile(path)) if path is not None else {}
    args.voice = args.voice or settings.get("voice_name", DEFAULT_VOICE)
    args.rate = args.rate or settings.get("speed", 1.0)
    if args.output is not None and args.output.suffix.lower() != ".wav":
        raise UsageError(f"-o {args.output}: vest writes WAV files; name it .wav")
    voice = load_voice(args.voice)  # VoiceError (exit 3) when it is not installed
    if args.output is not None:
        audio: Audio | None = None
        for sentence in sentences(text):
            part = voice.synthesize(sentence, speed=args.rate)
            audio = part if audio is None else audio.then(part)
        assert audio is not None
        try:
            write_wav(args.output, audio)
        except OSError as error:
            raise ConfigError(
                f"-o {args.output}: cannot write ({error.strerror or error})"
            ) from None
        print(f"{args.output}: {audio.seconds:.2f} s at {audio.rate_hz} Hz")
        return 0
    from engine.hardware.config_file import load_robot_config
    from engine.media.audio_devices import AlsaSpeaker

    config = load_robot_config(args.hardware) if args.hardware is not None else None
    device = args.device or (config.audio.speaker if config else None) or "default"
    clock = RealClock()
    playback = AlsaSpeaker(device)
    playback.open(voice.synthesize("a").rate_hz)  # a missing card is named: exit 3
    speaker = Speaker(voice, playback, clock, fallback_voice=EspeakVoice(), speed=args.rate)
    try:
        job = speaker.say(text)
        while not job.done():
            clock.sleep(0.05)
    finally:
        speaker.close()
        playback.close()
    failure = job.error()
    if failure is not None:
        raise ServiceError(f"could not say it: {failure}")
    return 0
