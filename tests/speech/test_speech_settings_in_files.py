"""A therapist's mistakes in the speech parts of scenarios, profiles and robot configs
are named with their place, before anything runs."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.cli import main
from engine.files.problems import LoadError
from engine.hardware.config_file import load_robot_config
from engine.scenario.scenario_file import load_scenario

ROOT = Path(__file__).resolve().parents[2]


def scenario_problems(tmp_path: Path, event: str) -> list[str]:
    path = tmp_path / "s.yaml"
    path.write_text(f"duration_s: 5\nevents:\n  - {event}\n", encoding="utf-8")
    with pytest.raises(LoadError) as caught:
        load_scenario(path, "s.yaml")
    return [str(problem) for problem in caught.value.problems]


@pytest.mark.parametrize(
    ("event", "message"),
    [
        ('{at: 1, hear: {text: "hi", wav: "a.wav"}}', "a.wav: file not found"),
        ("{at: 1, hear: {snr_db: 10}}", "hear takes text, wav or both"),
        ("{at: 1, hear: {wav: missing.wav}}", "missing.wav: file not found"),
        ('{at: 1, hear: "  "}', "hear has no words to say"),
        ('{at: 1, hear: {text: "hi", snr_db: 99}}', "'snr_db'"),
        ('{at: 1, hear: {text: "hi", loud: 3}}', "loud"),
        ("{at: 1, hear: [a, b]}", "must be text"),
    ],
)
def test_a_wrong_hear_event_is_named_where_it_is(tmp_path: Path, event: str, message: str) -> None:
    problems = scenario_problems(tmp_path, event)
    assert problems and all(p.startswith("s.yaml:3:") for p in problems), problems
    assert any(message in p for p in problems), problems


def test_a_profile_asking_for_a_voice_that_does_not_exist_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    profile = tmp_path / "kid.yaml"
    profile.write_text(
        "profile: kid\nparams:\n  voice: bob\n  speech_rate: 5\n  recognizer: siri\n",
        encoding="utf-8",
    )
    assert main(["validate", "trees/", "--profile", str(profile)]) == 1
    err = capsys.readouterr().err
    assert f"{profile}:3:10: no voice 'bob' (voices: hibari, joe, espeak)" in err
    assert f"{profile}:4:16: speech_rate must be 0.5..2, got 5" in err
    assert f"{profile}:5:15: no recognizer 'siri' (recognizers: moonshine, whisper)" in err


def test_a_robot_config_names_its_sound_devices(tmp_path: Path) -> None:
    base = (ROOT / "examples" / "robots" / "hbs2.yaml").read_text(encoding="utf-8")
    path = tmp_path / "robot.yaml"
    path.write_text(
        base + "\naudio:\n  microphone: plughw:1,0\n  speaker: none\n", encoding="utf-8"
    )
    audio = load_robot_config(path).audio
    assert (audio.microphone, audio.speaker) == ("plughw:1,0", None)
    path.write_text(base + "\naudio:\n  microfone: plughw:1,0\n", encoding="utf-8")
    with pytest.raises(LoadError) as caught:
        load_robot_config(path)
    assert "microfone" in str(caught.value)
