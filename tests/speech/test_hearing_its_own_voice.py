"""A robot owner measures how the robot hears its own voice (`vest hear --echo-of`): the
echo path as a scenario's `echo:` line, and whether the robot would stop for it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from engine.cli import main
from engine.media.audio import SPEECH_RATE_HZ, Audio, write_wav
from engine.sim.echo_path import EchoPath
from engine.speech.voice_models import default_voice
from engine.speech.voices import steady_voice

pytestmark = pytest.mark.models

SENTENCE = "Hello! I am the robot. Let us measure how my voice reaches my microphone today."


@pytest.fixture(scope="module")
def played() -> np.ndarray:
    voice = steady_voice(default_voice(None)[0])
    return voice.synthesize(SENTENCE).resampled(SPEECH_RATE_HZ).samples * 0.8


def recorded(played: np.ndarray, path: EchoPath) -> np.ndarray:
    heard = path.apply(played)
    return heard + np.random.default_rng(0).standard_normal(len(heard)).astype(np.float32) * 1e-3


@pytest.mark.parametrize(
    "room",
    [
        EchoPath(),
        EchoPath(delay_s=0.05, gain_db=0.0, rt60_s=0.5),
        EchoPath(gain_db=-12.0, rt60_s=0.2),
    ],
    ids=["default", "late and loud", "quiet and dry"],
)
def test_the_echo_path_is_measured_from_the_robot_s_own_sentence(
    played: np.ndarray, room: EchoPath
) -> None:
    found = EchoPath.measured(played, recorded(played, room))
    assert found.delay_s == pytest.approx(room.delay_s, abs=0.001)
    assert found.gain_db == pytest.approx(room.gain_db, abs=2.0)  # distortion takes a little
    assert found.rt60_s == pytest.approx(room.rt60_s, rel=0.25)


def test_the_owner_is_told_the_room_and_that_the_robot_would_not_stop_for_itself(
    played: np.ndarray, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write_wav(tmp_path / "played.wav", Audio(played, SPEECH_RATE_HZ))
    write_wav(tmp_path / "heard.wav", Audio(recorded(played, EchoPath(gain_db=-3.0)), 16000))
    heard, speaker = str(tmp_path / "heard.wav"), str(tmp_path / "played.wav")
    assert main(["hear", heard, "--echo-of", speaker, "--json"]) == 0
    told = json.loads(capsys.readouterr().out)
    assert told["echo"]["delay_s"] == 0.012 and told["stopped_itself"] == []
    assert main(["hear", heard, "--echo-of", speaker]) == 0
    out = capsys.readouterr().out
    assert "in a scenario: - {at: 0, echo: {delay_s: 0.012, gain_db: " in out
    assert "it would never stop for its own voice here" in out


@pytest.mark.parametrize(
    ("args", "why"),
    [
        (["--mic"], "--echo-of PLAYED.wav goes with one FILE.wav"),
        (["silence.wav"], "holds nothing that stands out of what was played"),
    ],
)
def test_a_recording_that_cannot_say_is_refused_in_words(
    played: np.ndarray,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    why: str,
) -> None:
    write_wav(tmp_path / "played.wav", Audio(played, SPEECH_RATE_HZ))
    write_wav(tmp_path / "silence.wav", Audio(np.zeros(SPEECH_RATE_HZ, np.float32), 16000))
    given = [str(tmp_path / a) if a.endswith(".wav") else a for a in args]
    code = main(["hear", *given, "--echo-of", str(tmp_path / "played.wav")])
    assert code != 0
    assert why in capsys.readouterr().err


def test_a_recording_started_too_late_or_a_silent_sentence_is_named(
    played: np.ndarray, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    late = EchoPath(delay_s=0.0).apply(played)
    write_wav(tmp_path / "played.wav", Audio(played, SPEECH_RATE_HZ))
    write_wav(tmp_path / "quiet.wav", Audio(np.zeros(16000, np.float32), 16000))
    heard = np.concatenate([np.zeros(12000, np.float32), late])  # 0.75 s in: recorded first
    write_wav(tmp_path / "late.wav", Audio(heard, 16000))
    assert (
        main(["hear", str(tmp_path / "late.wav"), "--echo-of", str(tmp_path / "played.wav")]) != 0
    )
    assert "0.75 s into the recording, later than 0.5 s" in capsys.readouterr().err
    assert main(["hear", str(tmp_path / "late.wav"), "--echo-of", str(tmp_path / "quiet.wav")]) != 0
    assert "quiet.wav: silent" in capsys.readouterr().err
