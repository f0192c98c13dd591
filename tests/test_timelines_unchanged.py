"""Refactoring changes no behaviour: every example scenario, with every profile, gives the
timeline and the JSON lines recorded in tests/golden_timelines/ with `vest run --fast`.

The demo's questions go through the real speech models on the virtual clock, and the same
on every machine. Two things would otherwise depend on the CPU's floating point (ONNX
Runtime picks other kernels on another CPU): a voice synthesized at run time (its samples,
and by a hair its length), and the frame where the VAD finds the end of speech (one
32 ms frame later on another machine moved "hears" a tick later there). So the demo's
lines are recordings checked in beside it (examples/scenarios/voices/: the same sound
everywhere), and on a virtual clock a scripted line is heard at its recording's end plus
0.4 s (the VAD's 0.3 s of silence and 0.1 s to spare), whatever frame the VAD ended it
on: the tolerance is 0.1 s of VAD disagreement (engine/robot_io/robot_speech.py,
`heard_when`). What the recognizer writes is the model's, prompted with the dialogs'
phrases: it can change when dialogs/default.yaml does; re-record the files then, and read
the diff."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.cli import main

pytestmark = pytest.mark.models

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = Path(__file__).parent / "golden_timelines"
CASES = sorted(
    (scenario, profile)
    for scenario in ("demo", "unplug_touch")
    for profile in ("none", "child", "adult")
)


def _run(capsys: pytest.CaptureFixture[str], scenario: str, profile: str, *extra: str) -> str:
    args = ["run", "--fast", "--scenario", f"examples/scenarios/{scenario}.yaml", *extra]
    if profile != "none":
        args += ["--profile", profile]
    assert main(args) == 0
    return capsys.readouterr().out


@pytest.mark.parametrize(("scenario", "profile"), CASES)
def test_the_timeline_is_the_one_recorded_before(
    scenario: str, profile: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    timeline = _run(capsys, scenario, profile).split("\n\n")[0].rstrip("\n")
    expected = (GOLDEN / f"{scenario}.{profile}.timeline").read_text().rstrip("\n")
    assert timeline == expected


@pytest.mark.parametrize(("scenario", "profile"), CASES)
def test_the_json_lines_are_the_ones_recorded_before(
    scenario: str, profile: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    actions = _run(capsys, scenario, profile, "--json")
    assert actions == (GOLDEN / f"{scenario}.{profile}.jsonl").read_text()
