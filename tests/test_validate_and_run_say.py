"""What `vest validate` and `vest run` say: the same checks from any folder, which checks
were skipped, the same warnings, and how long a run with the therapist's buttons lasts."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from engine.cli import main, validate_command

ROOT = Path(__file__).resolve().parents[1]
VEST = [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]


def test_outside_the_project_validate_and_run_find_the_simulated_vest_and_the_dialogs(
    tmp_path: Path,
) -> None:
    shutil.copytree(ROOT / "trees", tmp_path / "trees")  # a therapist's own folder

    def vest(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [*VEST, *args], cwd=tmp_path, capture_output=True, text=True, timeout=120
        )

    checked = vest("validate", "trees")
    assert checked.returncode == 0, checked.stderr
    assert "note:" not in checked.stderr  # the robot config was found: nothing skipped
    ran = vest("run", "--fast", "--speech", "text", "--duration", "8", "--trees", "trees")
    assert ran.returncode == 0, ran.stderr
    assert "buttons        lights the face green" in ran.stdout


def test_a_project_of_its_own_gets_our_buttons_only_with_our_demo_that_presses_them(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    (tmp_path / "trees").mkdir()  # a therapist's project: one tree, no button board
    shutil.copy(ROOT / "trees" / "hug.yaml", tmp_path / "trees")
    (tmp_path / "pat.yaml").write_text(
        "duration_s: 5\nevents:\n  - {at: 1.0, touch: {pad: chest, seconds: 1}}\n"
    )
    monkeypatch.chdir(tmp_path)
    run = ["run", "--fast", "--speech", "text", "--duration", "9", "--trees", "trees"]
    assert main([*run, "--scenario", "pat.yaml"]) == 0
    assert "buttons" not in capsys.readouterr().out  # our 'Well done' never joins it
    assert main(run) == 0  # our demo scenario, which presses our button: lent together
    assert "presses the button 'Well done'" in capsys.readouterr().out


def test_validate_says_which_checks_it_skipped_without_a_robot_config(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    monkeypatch.setattr(validate_command, "DEFAULT_HARDWARE", tmp_path / "none.yaml")
    assert main(["validate", str(ROOT / "trees" / "hug.yaml")]) == 0
    err = capsys.readouterr().err
    assert "pads, joints, devices and safety were not checked; give --hardware CONFIG" in err


def test_validate_warns_of_a_button_shown_only_while_a_missing_tree_runs_as_run_does(
    tmp_path: Path, capsys
) -> None:
    shutil.copytree(ROOT / "trees" / "parts", tmp_path / "parts")
    shutil.copytree(ROOT / "trees" / "buttons", tmp_path / "buttons")
    shutil.copy(ROOT / "trees" / "hug.yaml", tmp_path)
    assert main(["validate", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert err.count("shows only while 'finger_game' runs, and no such tree runs") == 1


@pytest.mark.realtime
def test_with_only_buttons_asked_for_the_robot_runs_until_ctrl_c(tmp_path: Path) -> None:
    process = subprocess.Popen(
        [
            *VEST,
            "run",
            "--speech",
            "text",
            "--buttons",
            "trees/buttons/session.yaml",
            "--view-port",
            "0",
        ],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stderr is not None
        said = ""
        told = []
        for line in process.stderr:  # until it says how long the session lasts
            told.append(line)
            if line.startswith("the session") or "Traceback" in line:
                said = line
                break
        assert said == "the session runs until Ctrl-C\n"
        assert any(line.startswith("vest run: no scenario plays") for line in told)
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=60)
    assert process.returncode == 0
