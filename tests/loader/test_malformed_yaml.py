"""Malformed tree files that used to escape as Python exceptions: now each is a problem.

Huge numbers, an alias inside itself, nesting deeper than Python's stack, an escape naming
no character, and include paths the operating system refuses (a file used as a folder, a
name too long, a NUL character, a symbolic link loop) each read as
``file:line:column: message (hint)``, through the loader and through ``vest validate``,
never as a traceback.
"""

from __future__ import annotations

import os
import re
import textwrap
from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.cli import main
from engine.files.problems import LoadError
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry

PROBLEM_LINE = re.compile(r"^\S.*:\d+:\d+: \S")
HUGE = "9" * 400  # more than a float holds (1e308)


def nested_sequences(levels: int) -> str:
    return "{Sequence: [" * levels + "{Say: {text: deep}}" + "]}" * levels


# (file name, tree text, the start of the one problem expected)
CASES = [
    (
        "huge_threshold.yaml",
        f"root:\n  Check: {{key: /sensors/force/left_n, above: {HUGE}}}\n",
        "tree.yaml:2:46: 'above' must be a number below 1e308",
    ),
    (
        "huge_between.yaml",
        f"root:\n  Check: {{key: /sensors/force/left_n, between: [0, {HUGE}]}}\n",
        "tree.yaml:2:48: 'between' item 2 must be a number below 1e308",
    ),
    (
        "huge_rate.yaml",
        f"rate_hz: {HUGE}\nroot:\n  Say: {{text: hi}}\n",
        "tree.yaml:1:10: 'rate_hz' must be a number below 1e308",
    ),
    (
        "too_many_digits.yaml",
        "root:\n  Wait: {seconds: " + "9" * 5000 + "}\n",
        "tree.yaml:2:19: bad value:",
    ),
    (
        "alias_in_itself.yaml",
        "name: c\nroot: &x\n  Sequence: [*x]\n",
        "tree.yaml:3:14: alias *x refers to itself: it is inside &x",
    ),
    (
        "alias_list_in_itself.yaml",
        "a: &x [*x]\n",
        "tree.yaml:1:8: alias *x refers to itself: it is inside &x",
    ),
    (
        "three_hundred_levels.yaml",
        f"name: d\nroot: {nested_sequences(300)}\n",
        "tree.yaml:2:",
    ),
    (
        "escape_beyond_unicode.yaml",
        'root:\n  Say: {text: "\\U0011FFFF"}\n',
        "tree.yaml:2:",
    ),
]


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def loader_problems(folder: Path, path: Path) -> list[str]:
    loader = TreeLoader(default_registry(), default_catalogue(), root_dir=folder)
    with pytest.raises(LoadError) as caught:
        loader.load(path)
    return [str(problem) for problem in caught.value.problems]


def validate(
    folder: Path, path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> list[str]:
    """``vest validate path`` run from ``folder``: its problem lines (exit 1, no traceback)."""
    monkeypatch.chdir(folder)
    assert main(["validate", str(path.relative_to(folder))]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert re.fullmatch(r"\d+ problems?", lines[-1]), err
    assert all(PROBLEM_LINE.match(line) for line in lines[:-1]), err
    return lines[:-1]


@pytest.mark.parametrize(("name", "text", "expected"), CASES, ids=[case[0] for case in CASES])
def test_a_malformed_file_is_one_problem_with_its_place(
    tmp_path: Path, name: str, text: str, expected: str
) -> None:
    [problem] = loader_problems(tmp_path, write(tmp_path, "tree.yaml", text))
    assert problem.startswith(expected)


@pytest.mark.parametrize(("name", "text", "expected"), CASES, ids=[case[0] for case in CASES])
def test_vest_validate_reports_a_malformed_file_in_words(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    name: str,
    text: str,
    expected: str,
) -> None:
    [line] = validate(tmp_path, write(tmp_path, "tree.yaml", text), capsys, monkeypatch)
    assert line.startswith(expected)


def test_three_hundred_nested_sequences_are_refused_for_their_depth(tmp_path: Path) -> None:
    [problem] = loader_problems(
        tmp_path, write(tmp_path, "tree.yaml", f"root: {nested_sequences(300)}\n")
    )
    assert "nested more than 100 levels deep" in problem


def test_a_tree_nested_twenty_composites_deep_still_loads(tmp_path: Path) -> None:
    path = write(tmp_path, "tree.yaml", f"root: {nested_sequences(20)}\n")
    loader = TreeLoader(default_registry(), default_catalogue(), root_dir=tmp_path)
    assert loader.load(path).root.type.name == "Sequence"


def test_an_escape_beyond_unicode_says_it_names_no_character(tmp_path: Path) -> None:
    [problem] = loader_problems(
        tmp_path, write(tmp_path, "tree.yaml", 'root:\n  Say: {text: "\\U0011FFFF"}\n')
    )
    assert "an escape here names no character" in problem


# -- include paths the operating system refuses ----------------------------------------------
def include(folder: Path, target: str) -> Path:
    return write(folder, "tree.yaml", f"root:\n  Subtree: {{file: {target}}}\n")


def loop(folder: Path) -> None:
    """parts/loop.yaml -> parts/back.yaml -> parts/loop.yaml."""
    (folder / "parts").mkdir()
    os.symlink("back.yaml", folder / "parts" / "loop.yaml")
    os.symlink("loop.yaml", folder / "parts" / "back.yaml")


def test_a_file_used_as_a_folder_is_named_as_the_reason(tmp_path: Path) -> None:
    write(tmp_path, "parts/greet.yaml", "root:\n  Say: {text: hi}\n")
    lines = loader_problems(tmp_path, include(tmp_path, "parts/greet.yaml/x.yaml"))
    assert lines == [
        "parts/greet.yaml/x.yaml:1:1: cannot read the file: Not a directory "
        "(a part of the path is a file, not a folder)",
        "tree.yaml:2:19: cannot include 'parts/greet.yaml/x.yaml'",
    ]


def test_a_name_too_long_for_the_file_system_is_named_as_the_reason(tmp_path: Path) -> None:
    lines = loader_problems(tmp_path, include(tmp_path, "a" * 300 + ".yaml"))
    assert lines[0].endswith("cannot read the file: File name too long (use a shorter file name)")
    assert lines[1] == f"tree.yaml:2:19: cannot include '{'a' * 300}.yaml'"


def test_a_nul_character_in_an_include_is_named(tmp_path: Path) -> None:
    lines = loader_problems(tmp_path, include(tmp_path, '"a\\0b.yaml"'))
    assert lines == [
        "a\\0b.yaml:1:1: the file name contains a NUL character (retype it)",
        "tree.yaml:2:19: cannot include 'a\\x00b.yaml'",
    ]


def test_an_include_through_a_symbolic_link_loop_is_named(tmp_path: Path) -> None:
    loop(tmp_path)
    lines = loader_problems(tmp_path, include(tmp_path, "parts/loop.yaml"))
    assert lines == [
        "parts/loop.yaml:1:1: cannot read the file: Too many levels of symbolic links "
        "(a symbolic link on the way points back to itself)",
        "tree.yaml:2:19: cannot include 'parts/loop.yaml'",
    ]


def test_a_tree_file_that_is_a_symbolic_link_loop_is_named(tmp_path: Path) -> None:
    loop(tmp_path)
    [line] = loader_problems(tmp_path, tmp_path / "parts" / "loop.yaml")
    assert line.startswith("parts/loop.yaml:1:1: cannot read the file: Too many levels")


@pytest.mark.parametrize(
    "target",
    ["parts/greet.yaml/x.yaml", "a" * 300 + ".yaml", '"a\\0b.yaml"', "parts/loop.yaml"],
    ids=["file_as_folder", "name_too_long", "nul", "symlink_loop"],
)
def test_vest_validate_reports_a_refused_include_in_words(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    target: str,
) -> None:
    if target == "parts/loop.yaml":
        loop(tmp_path)
    else:
        write(tmp_path, "parts/greet.yaml", "root:\n  Say: {text: hi}\n")
    lines = validate(tmp_path, include(tmp_path, target), capsys, monkeypatch)
    assert any(line.startswith("tree.yaml:2:19: cannot include ") for line in lines), lines


def test_vest_validate_of_a_folder_holding_a_symbolic_link_loop_names_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    loop(tmp_path)
    lines = validate(tmp_path, tmp_path / "parts", capsys, monkeypatch)
    assert lines[0].startswith("parts/back.yaml:1:1: cannot read the file: Too many levels")
