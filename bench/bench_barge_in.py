"""Barge-in: a person speaking over the robot stops it, and the robot never stops itself.

Run: ``.venv/bin/python bench/bench_barge_in.py`` (``--help``); about 6 minutes on 2 cores
(``--quick``: a short run that only shows it still works; ``--tuning``: the people over
the robot are the tuning children, on which the thresholds are chosen).

Everything goes the robot's way: the microphone's 64 ms pieces (as ALSA hands them over)
into the listener (:class:`engine.speech.listener.Listener`: echo canceller, Silero VAD,
the residual-echo check while the robot speaks, the recognizer), the robot's voice placed on
:class:`engine.speech.speaker.SelfHearing` as the speaker plays it, the room between
them the simulated vest's echo path (:class:`engine.sim.echo_path.EchoPath`).

- **Self-interruptions**: the robot's own sentences (every answer of dialogs/default.yaml
  and the demo's trees, hibari voice), each at volumes from 0.4 to 1.0 (all the safety
  envelope allows) through four echo paths (the default; 6 dB louder; a reverberant room;
  a speaker driven hard), nobody else talking: how many times the robot would have
  stopped itself. Target 0. Baselines in the same run: no canceller (the residual-echo
  check on the microphone itself) and SpeexDSP's canceller (``pyaec``) in place of AEC3.
- **Stop latency**: a person starts 0.6 to 1.2 s into a robot sentence, at 0, -6 and
  -12 dB against the robot's echo: from where the VAD finds their voice when it speaks
  alone to the end of the microphone's piece in which the listener says it began over the
  robot (the robot silences its speaker then), p50 and p90. Target: p90 <= 0.3 s. The
  people: the held-back children of bench/children_speech.py (the thresholds were chosen on
  the other children, ``--tuning``) and the joe and espeak-ng voices saying four questions
  (four others with ``--tuning``).
- **Understood**: what the listener heard of each of those, against what it hears of the
  same clip with nobody else talking (the same words).
- **Idle CPU**: the listener on 60 s of a quiet room, the robot silent: % of one core,
  with and without the canceller. Target < 1 %.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from children_speech import split_corpus  # noqa: E402

from engine.blackboard.catalogue import default_catalogue  # noqa: E402
from engine.clock import VirtualClock  # noqa: E402
from engine.dialogs.library import load_dialog  # noqa: E402
from engine.media.audio import SPEECH_RATE_HZ, Audio, noise  # noqa: E402
from engine.sim.echo_path import EchoPath  # noqa: E402
from engine.speech.echo_canceller import FRAME, Cancelled, EchoCanceller  # noqa: E402
from engine.speech.listener import Heard, Listener  # noqa: E402
from engine.speech.recognizer import Recognizer  # noqa: E402
from engine.speech.recognizers import NoWords, default_recognizer  # noqa: E402
from engine.speech.residual_echo import ResidualEcho  # noqa: E402
from engine.speech.speaker import SelfHearing  # noqa: E402
from engine.speech.vad import SileroVad, speech_detector  # noqa: E402
from engine.speech.voice_models import default_voice, load_voice  # noqa: E402
from engine.speech.voices import EspeakVoice, Voice, steady_voice  # noqa: E402

R = SPEECH_RATE_HZ
CHUNK = 1024  # 64 ms, as the robot's microphone hands audio over
ROOM_DBFS = -60.0
PATHS = {
    "default": EchoPath(),
    "louder": EchoPath(gain_db=0.0),
    "reverberant": EchoPath(rt60_s=0.8),
    "driven hard": EchoPath(distortion=1.0),
}
VOLUMES = (0.4, 0.6, 0.8, 1.0)
LEVELS_DB = (0.0, -6.0, -12.0)


class PassThrough:
    """No canceller, but the listener's residual-echo check while the robot speaks (a
    baseline)."""

    lag_samples = 0
    learned = True

    def cancel(self, microphone: np.ndarray, reference: np.ndarray) -> Cancelled:
        return Cancelled(microphone, reference)


class SpeexCanceller:
    """SpeexDSP's canceller (``pyaec``), with AEC3's interface, for the comparison."""

    name = "SpeexDSP"

    def __init__(self) -> None:
        from pyaec import Aec

        self._aec = Aec(FRAME, R // 4, R, True)
        self._mic = np.zeros(0, np.float32)
        self._ref = np.zeros(0, np.float32)
        self._heard = 0

    @property
    def lag_samples(self) -> int:
        return len(self._mic)

    @property
    def learned(self) -> bool:  # as AEC3's: after 1.5 s of the robot's voice
        return self._heard >= 1.5 * R

    def cancel(self, microphone: np.ndarray, reference: np.ndarray) -> Cancelled:
        self._heard += int(np.count_nonzero(reference))
        self._mic = np.concatenate([self._mic, microphone])
        self._ref = np.concatenate([self._ref, reference])
        whole = len(self._mic) // FRAME * FRAME
        out = np.zeros(whole, np.float32)
        for start in range(0, whole, FRAME):
            near = (np.clip(self._mic[start : start + FRAME], -1, 1) * 32767).astype(np.int16)
            far = (np.clip(self._ref[start : start + FRAME], -1, 1) * 32767).astype(np.int16)
            cleaned = self._aec.cancel_echo(near.tolist(), far.tolist())
            out[start : start + FRAME] = np.array(cleaned, np.float32) / 32767
        played = self._ref[:whole]
        self._mic, self._ref = self._mic[whole:], self._ref[whole:]
        return Cancelled(out, played)


@dataclass
class Ears:
    """One robot's canceller and residual-echo check: both learn the room as the robot
    speaks, so one serves every sentence in a room, as on a robot."""

    canceller: object
    residual_echo: ResidualEcho = field(default_factory=ResidualEcho)


@dataclass
class Run:
    """One pass of a robot sentence (and perhaps a person) through the listener."""

    onsets: list[float]
    heard: list[str]


def listen(
    robot: np.ndarray,
    path: EchoPath,
    person: np.ndarray | None,
    person_at_s: float,
    ears: Ears,
    recognizer: Recognizer | None,
    vad: SileroVad,
) -> Run:
    """``robot`` (16 kHz, at its volume) played from 0.5 s through ``path``, ``person``
    from ``person_at_s``; the speaker stops when the listener says a voice began over it."""
    clock = VirtualClock()
    hearing = SelfHearing()
    onsets: list[float] = []
    heard: list[str] = []
    robot_at = int(0.5 * R)
    hearing.played(Audio(robot, R), 0.5)
    hearing.speaking(0.5, 0.5 + len(robot) / R)
    length = robot_at + len(robot) + 3 * R
    if person is not None:
        length = max(length, int(person_at_s * R) + len(person) + 2 * R)
    room = noise(length / R, ROOM_DBFS, seed=len(robot)).samples[:length]
    people = np.zeros(length, np.float32)
    if person is not None:
        start = int(person_at_s * R)
        people[start : start + len(person)] = person
    echo = np.zeros(length, np.float32)
    heard_echo = path.apply(robot)[: length - robot_at]
    echo[robot_at : robot_at + len(heard_echo)] = heard_echo
    stopped = False

    def barged_in(onset_s: float) -> None:
        nonlocal stopped, echo
        onsets.append(onset_s)
        if stopped:
            return
        stopped = True  # the speaker stops now: what it played so far rings out
        played = max(0, int(clock.now() * R) - robot_at)
        hearing.quiet(clock.now())
        echo = np.zeros(length, np.float32)
        rang = path.apply(robot[:played])[: length - robot_at]
        echo[robot_at : robot_at + len(rang)] = rang

    detector = speech_detector(vad, children=True)
    detector.residual_echo = ears.residual_echo
    listener = Listener(
        detector,
        recognizer or NoWords(),
        clock,
        lambda h: heard.append(h.text) if isinstance(h, Heard) else None,
        self_hearing=hearing,
        canceller=ears.canceller,  # type: ignore[arg-type]
        on_barge_in=barged_in,
    )
    vad.reset()
    for end in range(CHUNK, length + 1, CHUNK):
        clock.advance(CHUNK / R)
        piece = room[end - CHUNK : end] + people[end - CHUNK : end] + echo[end - CHUNK : end]
        listener.hear(Audio(piece.astype(np.float32), R), end / R)
        if recognizer is not None:
            listener.settling.wait(listener.settled)
    listener.close()
    return Run(onsets, heard)


def voice_onset_s(samples: np.ndarray, vad: SileroVad) -> float:
    """Where the VAD finds a voice that speaks alone (its first frame at the detector's
    start threshold, 0.5): the onset a stop latency counts from."""
    vad.reset()
    for index in range(0, len(samples) - 511, 512):
        if vad(samples[index : index + 512]) >= 0.5:
            return index / R
    return 0.0


def words(text: str) -> str:
    return " ".join(re.sub(r"[^a-z' ]", " ", text.lower()).split())


def rms(samples: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(samples)) + 1e-12))


def robot_sentences(voice: Voice, limit: int) -> list[np.ndarray]:
    """The robot's own answers: every ``say`` of the default dialog, then the demo's."""
    dialog = load_dialog(ROOT / "dialogs" / "default.yaml", default_catalogue())
    said = [t.source for t in dialog.templates() if "{" not in t.source]
    said += [
        "Thank you for the hug.",
        "Hello, nice to see you.",
        "Well done! That was great.",
        "Let's play a counting game!",
        "Show me three fingers!",
        "Yes! That's three. Well done!",
        "The temperature is 72 degrees",
        "My name is H B S 2",
    ]
    said = list(dict.fromkeys(said))
    return [voice.synthesize(text).resampled(R).samples for text in said[:limit]]


def self_interruptions(sentences: list[np.ndarray], vad: SileroVad) -> None:
    """Each canceller on every sentence, volume and echo path, nobody else talking."""
    cancellers: dict[str, Callable[[], object]] = {
        "AEC3 (vest)": EchoCanceller,
        "SpeexDSP": SpeexCanceller,
        "none": PassThrough,
    }
    total = len(sentences) * len(VOLUMES) * len(PATHS)
    print(f"self-interruptions: {len(sentences)} sentences x {len(VOLUMES)} volumes x paths")
    for name, make in cancellers.items():
        per_path = {}
        for path_name, path in PATHS.items():
            ears = Ears(make())  # one a room, learning as it goes, as on a robot
            per_path[path_name] = sum(
                bool(listen(samples * volume, path, None, 0.0, ears, None, vad).onsets)
                for samples in sentences
                for volume in VOLUMES
            )
        shown = ", ".join(f"{p} {c}" for p, c in per_path.items())
        print(f"  {name:12s} {sum(per_path.values()):4d} of {total} stopped itself ({shown})")


def people_speaking(quick: bool, tuning: bool = False) -> list[tuple[str, np.ndarray]]:
    """The held-back children's clips (every 8th) and two voices' questions; ``tuning``:
    the tuning children's (every 6th) and other questions, to choose thresholds on."""
    chosen, held_back = split_corpus()
    if not tuning:
        chosen = held_back
    every = 40 if quick else 6 if tuning else 8
    people = [(clip.text, clip.audio.resampled(R).samples) for clip in chosen[::every]]
    questions = TUNING_QUESTIONS if tuning else QUESTIONS
    questions = questions[:1] if quick else questions
    for voice in (steady_voice(load_voice("joe")), EspeakVoice()):
        people += [(q, voice.synthesize(q).resampled(R).samples) for q in questions]
    return people


QUESTIONS = ["what is your name", "can we play a game", "stop please", "what is the temperature"]
TUNING_QUESTIONS = ["hello robot", "can you help me", "i want to stop", "how old are you"]


def barge_ins(sentences: list[np.ndarray], vad: SileroVad, quick: bool, tuning: bool) -> None:
    """People speaking over the robot: stop latency, and what was understood."""
    recognizer, _ = default_recognizer(None, children=True)
    people = people_speaking(quick, tuning)
    recognizer.listen_for([text for text, _ in people])
    robot, path, levels = sentences[:3], PATHS["default"], LEVELS_DB[:1] if quick else LEVELS_DB
    ears = Ears(EchoCanceller())
    for sentence in robot:  # the robot has spoken before: the canceller knows the room
        listen(sentence * 0.8, path, None, 0.0, ears, None, vad)
    latencies: dict[float, list[float]] = {level: [] for level in levels}
    missed = same = clean_right = over_right = 0
    for index, (text, samples) in enumerate(people):
        quiet = np.zeros(R // 10, np.float32)
        clean = " ".join(listen(quiet, path, samples * 0.5, 1.0, ears, recognizer, vad).heard)
        onset_s = voice_onset_s(samples, vad)
        for level_db in levels:
            sentence = robot[index % len(robot)] * 0.8
            person = samples * (rms(path.apply(sentence)) / rms(samples)) * 10 ** (level_db / 20)
            at_s = 1.1 + 0.6 * ((index * 7 + int(level_db)) % 5) / 4
            run = listen(sentence, path, person, at_s, ears, recognizer, vad)
            if run.onsets:  # found at the end of the microphone's piece that held it
                found_s = math.ceil(run.onsets[0] * R / CHUNK) * CHUNK / R
                latencies[level_db].append(max(0.0, found_s - (at_s + onset_s)))
            else:
                missed += 1
            heard = " ".join(run.heard)
            same += words(heard) == words(clean)
            clean_right += words(clean) == words(text)
            over_right += words(heard) == words(text)
    tried = len(people) * len(levels)
    every = [latency for each in latencies.values() for latency in each]
    print(f"barge-in: {len(people)} clips over the robot at {levels} dB: {tried} sentences")
    print(f"  not stopped: {missed}")
    for level_db, found in [*latencies.items(), ("all", every)]:
        p50, p90 = np.quantile(found, 0.5), np.quantile(found, 0.9)
        print(f"  stop latency at {level_db} dB: p50 {p50:.3f} s, p90 {p90:.3f} s")
    print("  (target: p90 <= 0.3 s, from where the VAD finds the voice alone)")
    print(f"  understood as with nobody talking: {same} of {tried}")
    print(f"  the very words: {over_right} over the robot, {clean_right} alone")


def idle_cpu(vad: SileroVad) -> None:
    """The listener on a quiet room, the robot silent, with and without the canceller."""
    room = noise(60.0, ROOM_DBFS, seed=1).samples
    for name, make in (("without canceller", None), ("with AEC3", EchoCanceller)):
        clock = VirtualClock()
        canceller = make() if make is not None else None
        listener = Listener(
            speech_detector(vad), NoWords(), clock, lambda h: None, canceller=canceller
        )  # type: ignore[arg-type]
        started = time.process_time()
        for end in range(CHUNK, len(room) + 1, CHUNK):
            clock.advance(CHUNK / R)
            listener.hear(Audio(room[end - CHUNK : end], R), end / R)
        used = time.process_time() - started
        print(f"idle listening {name}: {used / 60 * 100:.2f} % of one core (target < 1 %)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="a short run (under a minute)")
    parser.add_argument(
        "--tuning",
        action="store_true",
        help="people over the robot: the tuning children, to choose thresholds on",
    )
    args = parser.parse_args()
    vad = SileroVad()
    hibari = steady_voice(default_voice(None)[0])
    sentences = robot_sentences(hibari, 4 if args.quick else 60)
    self_interruptions(sentences, vad)
    barge_ins(sentences, vad, args.quick, args.tuning)
    idle_cpu(vad)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
