"""One failing part must not make the robot stutter: the rest of a behavior happens once."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_with_the_face_leds_unplugged_a_long_hug_is_answered_once(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    assert (
        main(["run", "--fast", "--json", "--scenario", "examples/scenarios/unplug_leds.yaml"]) == 0
    )
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    hug = [(a["event"], a["action"]) for a in lines if a.get("tree") == "hug"]
    # the call to the dark face, its failure, and one answer: no second try while hugged
    assert hug == [("action", "led"), ("outcome", "led"), ("action", "say")]
