"""A missing sound card is named and the rest runs (this machine has no sound card)."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.cli import main
from engine.clock import RealClock
from engine.hardware.config import AudioConfig
from engine.media.audio_devices import probe
from engine.robot_io.speech_assembly import build_speech

pytestmark = pytest.mark.models


def test_a_missing_card_is_named_by_the_probe() -> None:
    status = probe("microphone", "hw:9,9")
    assert not status.ok
    assert "microphone 'hw:9,9'" in status.detail


def test_a_robot_without_its_sound_card_hears_nothing_and_says_why() -> None:
    speech = build_speech(
        AudioConfig(microphone="hw:9,9", speaker="hw:9,9"),
        RealClock(),
        simulated=False,
        phrases=["what is your name"],
        settle=False,
    )
    try:
        assert "hw:9,9" in speech.problems["microphone"]
        job = speech.speaker.say("hello")
        clock = RealClock()
        stop = clock.event()
        for _ in range(200):
            if job.done():
                break
            clock.wait(stop, 0.05)
        assert job.done() and "hw:9,9" in str(job.error())
    finally:
        speech.close()


def test_vest_say_without_a_card_exits_3_naming_it(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["say", "hello", "--device", "hw:9,9"]) == 3
    assert "speaker 'hw:9,9' cannot be opened" in capsys.readouterr().err


def test_vest_hear_mic_without_a_card_exits_3_naming_it(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(Path(__file__).resolve().parents[2])
    assert main(["hear", "--mic", "--device", "hw:9,9"]) == 3
    assert "microphone 'hw:9,9' cannot be opened" in capsys.readouterr().err
