"""`vest validate` refuses what `vest run` refuses: the two share one set of checks, and
every command takes a profile by name or by path."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]
GREETING = """\
dialog: default
rules:
  - hear: [hello]
    say: Hello!
"""


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def problems_told(capsys: pytest.CaptureFixture[str], *argv: str) -> list[str]:
    """The problem lines a command printed before exiting 1 (without the final count)."""
    assert main(list(argv)) == 1
    return capsys.readouterr().err.strip().splitlines()[:-1]


def both_refuse(capsys: pytest.CaptureFixture[str], trees: Path, *run_args: str) -> list[str]:
    """What `vest validate` says of the folder above ``trees``, checked to be what
    `vest run` says when asked to run those trees."""
    validated = problems_told(capsys, "validate", str(trees.parent))
    ran = problems_told(capsys, "run", "--fast", "--trees", str(trees), *run_args)
    assert validated == ran
    return validated


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A therapist's folder beside the repository's robot config (run from the repository)."""
    monkeypatch.chdir(ROOT)
    write(tmp_path / "dialogs" / "default.yaml", GREETING)
    return tmp_path


def test_a_pad_beyond_the_twelve_the_touch_chip_has_is_refused_by_both(project, capsys):
    trees = project / "trees"
    write(
        trees / "pat.yaml",
        """\
        name: pat
        root:
          Sequence:
            - Check: {key: /sensors/touch/pads, item: 99999, equals: true}
            - Say: {text: thanks}
        """,
    )
    [line] = both_refuse(capsys, trees, "--dialogs", str(project / "dialogs"))
    assert line.startswith(f"{trees / 'pat.yaml'}:4:7: item 99999 is not in /sensors/touch/pads")
    assert "use an item from 0 to 11" in line


def test_a_device_key_naming_no_device_of_the_robot_is_refused_with_the_nearest(project, capsys):
    trees = project / "trees"
    write(
        trees / "check.yaml",
        """\
        name: check
        root:
          Sequence:
            - Check: {key: /devices/tuoch/ok, equals: false}
            - Say: {text: my back pads are off}
        """,
    )
    [line] = both_refuse(capsys, trees, "--dialogs", str(project / "dialogs"))
    assert line == (
        f"{trees / 'check.yaml'}:4:20: unknown blackboard key '/devices/tuoch/ok' "
        "(did you mean '/devices/touch/ok'?)"
    )


def test_two_dialogs_with_one_name_are_refused_by_both_once(project, capsys):
    write(project / "dialogs" / "again.yaml", GREETING)
    validated = problems_told(capsys, "validate", str(project / "dialogs"))
    ran = problems_told(capsys, "run", "--fast", "--dialogs", str(project / "dialogs"))
    assert (
        validated
        == ran
        == [
            f"{project / 'dialogs' / 'default.yaml'}:1:1: two dialogs are named 'default' "
            f"(also {project / 'dialogs' / 'again.yaml'}) "
            "(rename one: trees name a dialog by its name)"
        ]
    )


def test_a_remote_command_the_robot_does_not_know_is_refused_in_a_scenario(project, capsys):
    scenario = write(
        project / "dance.yaml",
        """\
        duration_s: 3
        events:
          - {at: 1.0, cloud: {type: dnace, args: {}}}
        """,
    )
    validated = problems_told(capsys, "validate", str(scenario))
    ran = problems_told(capsys, "run", "--fast", "--scenario", str(scenario))
    assert (
        validated
        == ran
        == [f"{scenario}:3:5: no remote command type 'dnace' (types: say, led, move, read)"]
    )


def test_a_fault_on_a_device_the_robot_does_not_have_is_refused_by_validate_too(project, capsys):
    scenario = write(
        project / "unplug.yaml",
        "duration_s: 5\nevents:\n  - {at: 1.0, unplug: {device: tuoch}}\n",
    )
    [line] = problems_told(capsys, "validate", str(scenario))
    assert line == (
        f"{scenario}:3:5: no device 'tuoch' in examples/robots/sim.yaml (did you mean 'touch'?)"
    )


def test_a_dialogs_folder_that_does_not_exist_is_named_by_validate_as_by_run(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["validate", "trees/", "--dialogs", "/nonexistent"]) == 1
    assert capsys.readouterr().err == "vest validate: --dialogs /nonexistent: no such folder\n"


def test_a_broken_dialog_is_told_once_as_written_and_blames_no_tree(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path / "dialogs" / "default.yaml", GREETING.replace("Hello!", "'{nope}'"))
    write(
        tmp_path / "trees" / "talk.yaml",
        """\
        name: talk
        root:
          Sequence:
            - OnEvent: {key: /speech/heard, save_as: /vars/heard}
            - Reply: {heard: /vars/heard}
        """,
    )
    told = problems_told(capsys, "validate", "trees/", "dialogs/")
    assert told == [
        "dialogs/default.yaml:4:10: unknown template field {nope} "
        "(name a blackboard key, e.g. {/vars/name})"
    ]
    ran = problems_told(
        capsys,
        "run",
        "--fast",
        "--hardware",
        str(ROOT / "examples/robots/sim.yaml"),
        "--scenario",
        str(ROOT / "examples/scenarios/unplug_touch.yaml"),
    )
    assert ran == told  # and no "no dialog named 'default'" for the tree using it


def test_render_takes_a_profile_by_name_as_run_does(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["render", "trees/touch_thanks.yaml", "--profile", "child"]) == 0
    assert "Thank you, friend!" in capsys.readouterr().out
    assert (
        main(["render", "trees/touch_thanks.yaml", "--profile", "trees/profiles/child.yaml"]) == 0
    )
    assert "Thank you, friend!" in capsys.readouterr().out


def test_a_profile_name_that_does_not_exist_is_told_with_the_nearest(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    for command in (["render", "trees/hug.yaml"], ["run", "--fast"]):
        assert main([*command, "--profile", "chlid"]) == 1
        assert capsys.readouterr().err == (
            f"vest {command[0]}: --profile chlid: no such profile (did you mean 'child'?)\n"
        )


def test_validate_checks_the_trees_with_a_profile_given_by_name_or_path(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    assert main(["validate", "trees/", "--profile", "child"]) == 0
    capsys.readouterr()
    profile = write(tmp_path / "kid.yaml", "profile: kid\nparams:\n  hug_treshold_n: 2.0\n")
    [line] = problems_told(capsys, "validate", "trees/", "--profile", str(profile))
    assert line.startswith(f"{profile}:3:19: no tree in the trees given declares parameter")
    assert "(did you mean 'hug_threshold_n'?)" in line


def test_a_tree_answering_from_dialogs_that_are_not_there_is_refused_by_both(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)  # a dialogs/ here, without the dialog the tree answers from
    (tmp_path / "dialogs").mkdir()
    trees = tmp_path / "trees"
    write(
        trees / "talk.yaml",
        """\
        name: talk
        root:
          Sequence:
            - OnEvent: {key: /speech/heard, save_as: /vars/heard}
            - Reply: {heard: /vars/heard}
        """,
    )
    robot = ("--hardware", str(ROOT / "examples/robots/sim.yaml"))
    scenario = ("--scenario", str(ROOT / "examples/scenarios/unplug_touch.yaml"))
    [line] = both_refuse(capsys, trees, *robot, *scenario)
    assert line == "trees/talk.yaml:5:7: no dialog named 'default' (add dialogs/NAME.yaml)"
