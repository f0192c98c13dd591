"""The therapist guide's examples, run: every YAML example validates in a copy of the
project, the timelines and pictures it shows are what vest prints, and its error example
is the message vest gives. A guide that drifts from the engine fails here."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]
GUIDE = ROOT / "docs" / "therapist-guide.md"
BLOCK = re.compile(r"```(\w*)\n(.*?)```", re.S)


def blocks(kind: str) -> list[str]:
    return [text for lang, text in BLOCK.findall(GUIDE.read_text()) if lang == kind]


def placed() -> dict[str, str]:
    """The guide's YAML examples that name their file on their first line."""
    files = {}
    for text in blocks("yaml"):
        first = text.splitlines()[0]
        if first.startswith("# ") and first.endswith(".yaml"):
            files[first.removeprefix("# ")] = text
    return files


def shown_after(command: str) -> list[str]:
    """The lines of the block the guide shows after the ``sh`` block running ``command``."""
    text = GUIDE.read_text()
    closing = text.index("```", text.index(command) + len(command))  # the sh block's end
    block = BLOCK.search(text, closing + 3)
    assert block is not None
    return [line.rstrip() for line in block.group(2).splitlines() if line.strip()]


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of the project with the guide's files written where it says."""
    for folder in ("trees", "dialogs", "examples"):
        shutil.copytree(ROOT / folder, tmp_path / folder)
    for name, text in placed().items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run_out(capsys: pytest.CaptureFixture[str], *args: str) -> list[str]:
    assert main(list(args)) == 0
    out = capsys.readouterr().out.split("\n\n")[0]
    return [line.rstrip() for line in out.splitlines()]


def test_the_guide_places_its_examples_where_a_therapist_would() -> None:
    assert set(placed()) >= {
        "trees/tickles.yaml",
        "trees/hug.yaml",
        "dialogs/pets.yaml",
        "dialogs/ask_first.yaml",
        "trees/profiles/calm_child.yaml",
        "examples/scenarios/tickles_test.yaml",
        "trees/buttons/my_session.yaml",
        "trees/two_pats.yaml",
        "examples/scenarios/two_pats_test.yaml",
    }


def test_every_example_of_the_guide_validates(project: Path, capsys) -> None:
    assert main(["validate", "trees/", "dialogs/", "examples/scenarios/"]) == 0
    assert "ok:" in capsys.readouterr().out


def test_the_hug_shown_is_the_hug_shipped() -> None:
    assert (
        placed()["trees/hug.yaml"].removeprefix("# trees/hug.yaml\n")
        == (ROOT / "trees" / "hug.yaml").read_text()
    )


def test_the_safety_section_shown_is_the_simulated_vest_s() -> None:
    [safety] = [text for text in blocks("yaml") if text.startswith("safety:")]
    assert safety in (ROOT / "examples" / "robots" / "sim.yaml").read_text()


def test_the_tickles_diary_is_what_the_robot_does(project: Path, capsys) -> None:
    command = "vest run --fast --speech text --scenario examples/scenarios/tickles_test.yaml"
    printed = run_out(capsys, *command.split()[1:])
    assert printed == shown_after(command)


def test_the_two_pats_diary_is_what_the_robot_does(project: Path, capsys) -> None:
    command = "vest run --fast --speech text --scenario examples/scenarios/two_pats_test.yaml"
    printed = run_out(capsys, *command.split()[1:])
    assert printed == shown_after(command)


def test_the_profile_of_the_guide_gives_a_slow_child_longer_for_two_pats(
    project: Path, capsys
) -> None:
    scenario = project / "slow_pats.yaml"
    scenario.write_text(
        "duration_s: 9\nevents:\n"
        "  - {at: 1.0, touch: {pad: middle_back, seconds: 0.3}}\n"
        "  - {at: 6.0, touch: {pad: middle_back, seconds: 0.3}}\n"
    )
    run = ["run", "--fast", "--speech", "text", "--scenario", str(scenario)]
    assert not any("two_pats" in line for line in run_out(capsys, *run))  # 5 s apart
    printed = run_out(capsys, *run, "--profile", "calm_child")
    assert '    6.00  two_pats       says "Two pats! Are we playing?"' in printed


def test_the_demo_diary_shown_is_part_of_the_demo(capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    printed = run_out(capsys, "run", "--fast", "--speech", "text")
    shown = shown_after("vest run --fast --speech text      #")
    assert all(line in printed for line in shown)


def test_the_vest_drawn_is_the_one_vest_keys_draws(capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    assert main(["keys", "--pads"]) == 0
    printed = [line.rstrip() for line in capsys.readouterr().out.splitlines()]
    shown = shown_after("vest keys --pads")
    start = printed.index(shown[0])
    assert printed[start : start + len(shown)] == shown


def test_the_error_example_is_the_message_vest_gives(project: Path, capsys) -> None:
    tickles = project / "trees" / "tickles.yaml"
    tickles.write_text(tickles.read_text().replace("[left_shoulder,", "[left_sholder,"))
    assert main(["validate", "trees/"]) == 1
    [example] = [line for line in blocks("") if "left_sholder" in line]
    assert example.strip() in capsys.readouterr().err


def test_the_buttons_of_the_guide_take_over(project: Path, capsys) -> None:
    scenario = project / "pressing.yaml"
    scenario.write_text("duration_s: 3\nevents:\n  - {at: 1.0, press: Hello Sam}\n")
    buttons = "trees/buttons/my_session.yaml"
    printed = run_out(
        capsys,
        "run",
        "--fast",
        "--speech",
        "text",
        "--scenario",
        str(scenario),
        "--buttons",
        buttons,
    )
    assert '    1.00  buttons        says "Hello Sam! I am happy to see you."' in printed


def test_the_profile_of_the_guide_softens_the_hug(project: Path, capsys) -> None:
    scenario = project / "hugging.yaml"
    scenario.write_text("duration_s: 3\nevents:\n  - {at: 1.0, squeeze: {left_n: 3, right_n: 3}}\n")
    printed = run_out(
        capsys, "run", "--fast", "--speech", "text", "--scenario", str(scenario),
        "--profile", "calm_child",
    )  # fmt: skip
    assert '    1.00  hug            says "A gentle hug, thank you."' in printed
