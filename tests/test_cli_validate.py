"""``vest validate``: "ok" and exit 0 for good files; every problem as file:line:column, exit 1.

Bad input never gives a Python traceback. Most tests call ``engine.cli.main`` in-process;
one runs the installed command in a subprocess, as a therapist would.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from engine.cli import main

REPO = Path(__file__).resolve().parents[1]
PROBLEM_LINE = re.compile(r"^\S+:\d+:\d+: \S")


def vest_command() -> list[str]:
    """The installed ``vest`` script (beside this Python, or on PATH), else its entry point."""
    script = shutil.which("vest", path=str(Path(sys.executable).parent)) or shutil.which("vest")
    if script:
        return [script]
    return [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def problem_lines(stderr: str) -> list[str]:
    """The problem lines of ``vest validate``'s report (without the final count)."""
    lines = stderr.strip().splitlines()
    assert re.fullmatch(r"\d+ problems?", lines[-1]), stderr
    return lines[:-1]


@pytest.fixture
def broken(tmp_path: Path) -> Path:
    """A trees folder with one good tree and one with two problems."""
    write(
        tmp_path,
        "trees/good.yaml",
        """\
        name: good
        params:
          rest_s: 3.0
        root:
          Cooldown:
            seconds: ${rest_s}
            child:
              Say: {text: hi}
        """,
    )
    write(
        tmp_path,
        "trees/bad.yaml",
        """\
        name: bad
        root:
          Sequence:
            - Chek: {key: /sensors/touch/any, equals: true}
            - SetLed: {color: pinkk}
        """,
    )
    return tmp_path / "trees"


def test_the_repository_files_are_ok(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        [
            "validate",
            str(REPO / "trees"),
            str(REPO / "dialogs"),
            str(REPO / "examples" / "scenarios"),
        ]
    )
    out, err = capsys.readouterr()
    assert (code, err) == (0, "")
    assert out.startswith("ok")


def test_a_broken_tree_is_listed_problem_by_problem_with_exit_1(
    broken: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["validate", str(broken)]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert problem_lines(err) == [
        f"{broken / 'bad.yaml'}:4:7: unknown node type 'Chek' (did you mean 'Check'?)",
        f"{broken / 'bad.yaml'}:5:23: unknown color 'pinkk' (did you mean 'pink'? "
        "colors: off, black, white, red, green, blue, yellow, orange, pink, purple, cyan, "
        "magenta, warm_white, or #RRGGBB)",
    ]
    assert err.strip().endswith("2 problems")


def test_problems_of_several_files_are_all_listed(
    broken: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (broken / "latin.yaml").write_bytes(b"root:\n  Say: {text: caf\xe9}\n")
    write(broken, "dup.yaml", "root:\n  Say: {text: a}\nroot:\n  Say: {text: b}\n")
    assert main(["validate", str(broken)]) == 1
    lines = problem_lines(capsys.readouterr().err)
    assert all(PROBLEM_LINE.match(line) for line in lines), lines
    assert [Path(line.split(":")[0]).name for line in lines] == [
        "bad.yaml",
        "bad.yaml",
        "dup.yaml",
        "latin.yaml",
    ]


def test_a_profile_setting_a_parameter_no_tree_declares_suggests_the_nearest(
    broken: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    profile = write(broken, "profiles/kid.yaml", "profile: kid\nparams:\n  rest: 2.0\n")
    assert main(["validate", str(profile)]) == 1
    assert problem_lines(capsys.readouterr().err) == [
        f"{profile}:3:9: no tree in {broken}/ declares parameter 'rest' (did you mean 'rest_s'?)"
    ]


def test_a_profile_value_of_the_wrong_kind_is_shown_at_the_profile_line(
    broken: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (broken / "bad.yaml").unlink()
    profile = write(broken, "profiles/kid.yaml", "profile: kid\nparams:\n  rest_s: soon\n")
    assert main(["validate", str(profile)]) == 1
    [line] = problem_lines(capsys.readouterr().err)
    assert line.startswith(
        f"{profile}:3:11: profile 'kid' sets 'rest_s' to 'soon', but the tree expects number"
    )


def test_a_missing_path_is_reported_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "trees" / "hugg.yaml"
    assert main(["validate", str(missing)]) == 1
    [line] = problem_lines(capsys.readouterr().err)
    assert line.startswith(f"{missing}:1:1: ")


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("binary.yaml", bytes(range(256))),
        ("latin.yaml", b"root:\n  Say: {text: caf\xe9}\n"),
        ("tag.yaml", b"root:\n  Say: {text: !!python/object/apply:os.getcwd []}\n"),
        ("tabs.yaml", b"root:\n\tSay: {text: hi}\n"),
        ("control.yaml", b"root:\n  Say: {text: hi}\n  \x0c\n"),
        ("two_documents.yaml", b"root:\n  Say: {text: a}\n---\nroot:\n  Say: {text: b}\n"),
        ("list.yaml", b"- Say: {text: hi}\n"),
        ("empty.yaml", b""),
        ("huge.yaml", b"#" * (1024 * 1024 + 1)),
    ],
)
def test_bad_input_never_gives_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, content: bytes
) -> None:
    path = tmp_path / name
    path.write_bytes(content)
    assert main(["validate", str(path)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert all(PROBLEM_LINE.match(line) for line in problem_lines(err)), err


def test_the_installed_command_validates_and_fails_in_words(broken: Path) -> None:
    (broken / "latin.yaml").write_bytes(b"root:\n  Say: {text: caf\xe9}\n")
    (broken / "folder.yaml").mkdir()
    good = subprocess.run(
        [*vest_command(), "validate", "trees/good.yaml"],
        cwd=broken.parent,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    bad = subprocess.run(
        [*vest_command(), "validate", "trees"],
        cwd=broken.parent,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert (good.returncode, good.stdout.strip()) == (0, "ok: 1 file")
    assert bad.returncode == 1
    assert "Traceback" not in bad.stderr
    assert problem_lines(bad.stderr) == [
        "trees/bad.yaml:4:7: unknown node type 'Chek' (did you mean 'Check'?)",
        "trees/bad.yaml:5:23: unknown color 'pinkk' (did you mean 'pink'? "
        "colors: off, black, white, red, green, blue, yellow, orange, pink, purple, cyan, "
        "magenta, warm_white, or #RRGGBB)",
        "trees/folder.yaml:1:1: is a folder, not a file",
        "trees/latin.yaml:2:18: byte 0xE9 is not UTF-8 text (save the file as UTF-8)",
    ]


def test_two_trees_of_one_folder_with_one_name_are_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = "name: greeter\nroot:\n  Say: {text: hi}\n"
    write(tmp_path, "a.yaml", tree)
    write(tmp_path, "b.yaml", tree)
    assert main(["validate", str(tmp_path)]) == 1
    assert f"{tmp_path / 'b.yaml'}:1:7: two trees are named 'greeter'" in capsys.readouterr().err


def test_a_misspelt_root_is_recognised_as_a_tree_with_a_suggestion(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write(tmp_path, "a.yaml", "rot:\n  Say: {text: hi}\n")
    assert main(["validate", str(tmp_path / "a.yaml")]) == 1
    assert "unknown field 'rot' (did you mean 'root'?)" in capsys.readouterr().err
