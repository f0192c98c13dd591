"""End to end on the simulated vest: people speak into the room, the robot hears them
through the real models, answers with its real voice, and never answers itself."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from engine.cli import main
from engine.media.audio import read_wav, write_wav

pytestmark = pytest.mark.models

ROOT = Path(__file__).resolve().parents[2]


def run(tmp_path: Path, capsys: pytest.CaptureFixture[str], events: str, *extra: str) -> list[dict]:
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(f"duration_s: 14\nevents:\n{events}", encoding="utf-8")
    args = [
        "run",
        "--fast",
        "--json",
        "--trees",
        "trees/dialog.yaml",
        "trees/iot_command.yaml",
        "--scenario",
        str(scenario),
        *extra,
    ]
    assert main(args) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines() if line]
    return [line for line in lines if line["event"] == "action"]


def said(actions: list[dict]) -> list[str]:
    return [a["args"]["text"] for a in actions if a["action"] == "say"]


@pytest.fixture(autouse=True)
def in_repo(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def test_the_child_asks_and_the_robot_answers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    actions = run(
        tmp_path,
        capsys,
        """\
  - {at: 1.0, hear: "what is your name"}
  - {at: 5.0, hear: {text: "do you like animals", snr_db: 10}}
  - {at: 10.0, hear: "yes, I have a cat"}
""",
    )
    assert said(actions) == [
        "My name is H B S 2",
        "I love animals. Do you have a pet?",
        "How lovely! Pets are good friends.",
    ]
    assert 1.0 < actions[0]["t"] < 3.5  # after the question ended, not before


def test_the_robot_does_not_answer_its_own_voice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the operator makes the robot say a question the dialog answers; its microphone hears
    # the echo in the room, and ignores it
    actions = run(
        tmp_path,
        capsys,
        """\
  - {at: 1.0, cloud: {type: say, args: {text: "What is your name?"}}}
""",
    )
    assert said(actions) == ["What is your name?"]


def test_a_recording_in_the_scenario_is_heard(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from engine.speech.voice_models import load_voice

    write_wav(
        tmp_path / "question.wav", load_voice("espeak").synthesize("what is your favorite color")
    )
    actions = run(tmp_path, capsys, "  - {at: 1.0, hear: {wav: question.wav}}\n")
    assert said(actions) == ["My favorite color is blue. My vest is blue."]


def test_what_the_robot_says_is_kept_as_wav_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "said"
    run(tmp_path, capsys, '  - {at: 1.0, hear: "what is your name"}\n', "--audio-out", str(out))
    (kept,) = sorted(out.glob("*.wav"))
    assert kept.name == "001-robot.wav"  # never the words: a sentence may quote a person
    assert kept.stat().st_mode & 0o077 == 0 and out.stat().st_mode & 0o077 == 0
    assert 1.0 < read_wav(kept).seconds < 4.0


def test_text_mode_skips_the_models(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    actions = run(
        tmp_path, capsys, '  - {at: 1.0, hear: "what is your name"}\n', "--speech", "text"
    )
    assert said(actions) == ["My name is H B S 2"]
    assert actions[0]["t"] == 1.0
