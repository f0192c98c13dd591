"""vest hear, vest say -o and vest dialogs check, as a therapist or developer uses them."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from engine.cli import main
from engine.media.audio import Audio, read_wav, write_wav
from engine.speech.voices import Voice

pytestmark = pytest.mark.models

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def in_repo(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def test_say_writes_the_robot_s_voice_to_a_wav(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "hello.wav"
    assert main(["say", "Hello. I am the robot.", "-o", str(out)]) == 0
    audio = read_wav(out)
    assert audio.rate_hz == 24000 and 1.0 < audio.seconds < 4.0  # the hibari voice


def test_hear_says_what_it_heard_the_rule_and_the_answer_per_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], voices: dict[str, Voice]
) -> None:
    question, silence = tmp_path / "question.wav", tmp_path / "silence.wav"
    # the steady voice: `vest say` samples its voice's noise, and a rare rendering makes
    # Whisper add a line of its own ("... Here we go."), which the matcher rightly refuses
    write_wav(question, voices["joe"].synthesize("What is the temperature?"))
    write_wav(silence, Audio.silence(2.0))
    capsys.readouterr()
    assert main(["hear", "--json", str(question), str(silence)]) == 0
    first, second = (json.loads(line) for line in capsys.readouterr().out.splitlines())
    # this machine's: at least the 0.2 s wait after a whole phrase, or recognizing it
    latency_s = first.pop("latency_s")
    assert isinstance(latency_s, float) and latency_s >= 0.2
    assert first == {
        "file": str(question),
        "heard": "What is the temperature?",
        "rule": "temperature",
        "score": 1.0,
        "answer": "The temperature is [temperature_f] degrees",
        "asks": None,
    }
    assert second == {
        "file": str(silence),
        "heard": None,
        "rule": None,
        "score": None,
        "answer": None,
        "asks": None,
        "latency_s": None,
    }


def test_hear_takes_a_typed_phrase_as_the_robot_would_hear_it_spoken(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["hear", "--json", "--text", "What is the temperature?"]) == 0
    heard = json.loads(capsys.readouterr().out)
    assert heard["file"] == "'What is the temperature?'"
    assert (heard["rule"], heard["answer"]) == (
        "temperature",
        "The temperature is [temperature_f] degrees",
    )


def test_hear_refuses_an_empty_typed_phrase(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["hear", "--text", "  "]) == 2
    assert "a phrase of 1 to 400 characters" in capsys.readouterr().err


def test_hear_refuses_a_file_that_is_not_a_wav(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = tmp_path / "notes.wav"
    text.write_text("not audio")
    assert main(["hear", str(text)]) == 1
    assert f"{text}: not a WAV file" in capsys.readouterr().err
    text.write_text("hello\n")  # too short for the header: the reason is still said
    assert main(["hear", str(text)]) == 1
    assert f"{text}: not a WAV file (cut short)" in capsys.readouterr().err


def test_dialogs_check_refuses_a_phrase_two_rules_share_before_hearing_anything(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "play.yaml").write_text(
        """\
dialog: play
rules:
  - id: play
    hear: ["do you want to play", "let us play"]
    say: "Yes!"
  - id: play_ball
    hear: ["do you want to play ball", "let us play"]
    say: "Throw it!"
""",
        encoding="utf-8",
    )
    assert main(["dialogs", "check", str(tmp_path), "--quick"]) == 1
    err = capsys.readouterr().err
    assert "rules 'play' (line 3) and 'play_ball' both listen for 'let us play'" in err


def test_dialogs_check_passes_the_default_dialog_quickly(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["dialogs", "check", "--quick"]) == 0
    assert "0 problem(s)" in capsys.readouterr().out


def test_hear_follows_a_conversation_in_one_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from engine.speech.voice_models import load_voice

    joe = load_voice("joe")
    pause = Audio.silence(1.0, 22050)
    question = joe.synthesize("Do you like animals?")
    answer = joe.synthesize("No.")
    write_wav(tmp_path / "talk.wav", pause.then(question).then(pause).then(answer).then(pause))
    assert main(["hear", "--json", str(tmp_path / "talk.wav")]) == 0
    rules = [json.loads(line)["rule"] for line in capsys.readouterr().out.splitlines()]
    assert rules == ["pets", "no_pet"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["hear"], 'give WAV files to hear, --text "a phrase", or --mic'),
        (["hear", "--mic", "x.wav"], "give WAV files or --text, or --mic, not both"),
        (["say", "  ...  "], "nothing to say"),
    ],
)
def test_a_wrong_command_line_exits_2(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(args) == 2
    assert message in capsys.readouterr().err
