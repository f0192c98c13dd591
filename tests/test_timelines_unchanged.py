"""Refactoring changes no behaviour: every example scenario, with every profile, gives the
timeline and the JSON actions recorded in tests/golden_timelines/ with `vest run --fast`.

The demo's questions go through the real speech models, deterministically on the virtual
clock. The recognizer is prompted with the dialogs' phrases, so what it writes can change
when dialogs/default.yaml does: re-record the demo's files then, and read the diff."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.cli import main

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
def test_the_json_actions_are_the_ones_recorded_before(
    scenario: str, profile: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    actions = _run(capsys, scenario, profile, "--json")
    assert actions == (GOLDEN / f"{scenario}.{profile}.jsonl").read_text()
