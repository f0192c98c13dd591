"""Trees that validated but could never do what they say are refused when they load.

A Check comparing a true/false key with the text "true", a key with a dot (py_trees reads
it as attribute access at every tick), ``item:`` on a key that is not a list, OnEvent on
a /vars/ key (variables never hold events), a template format that cannot format the
key's value: each is one problem at its place, with a hint.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import load_dialog
from engine.files.problems import LoadError
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry
from engine.testing import TreeHarness


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def problems_of(folder: Path, text: str) -> list[str]:
    loader = TreeLoader(default_registry(), default_catalogue(), root_dir=folder)
    with pytest.raises(LoadError) as caught:
        loader.load(write(folder, "tree.yaml", text))
    return [str(problem) for problem in caught.value.problems]


def check(key: str, comparison: str) -> str:
    return (
        f"root:\n  Sequence:\n    - Check: {{key: {key}, {comparison}}}\n    - Say: {{text: ok}}\n"
    )


# -- Check: a comparison with a value the key never holds -------------------------------------
@pytest.mark.parametrize(
    ("key", "comparison", "expected"),
    [
        (
            "/sensors/touch/any",
            'equals: "true"',
            "/sensors/touch/any holds true/false, never 'true' (write true without quotes)",
        ),
        (
            "/sensors/touch/any",
            "not_equals: 'no'",
            "/sensors/touch/any holds true/false, never 'no' (write false without quotes)",
        ),
        (
            "/sensors/force/left_n",
            'equals: "6"',
            "/sensors/force/left_n holds a number, never '6' (write 6 without quotes)",
        ),
        (
            "/sensors/force/left_n",
            "equals: true",
            "/sensors/force/left_n holds a number, never True",
        ),
        (
            "/devices/touch/ok",
            "equals: hello",
            "/devices/touch/ok holds true/false, never 'hello' (write true or false",
        ),
    ],
)
def test_a_check_against_a_value_the_key_never_holds_is_refused(
    tmp_path: Path, key: str, comparison: str, expected: str
) -> None:
    [problem] = problems_of(tmp_path, check(key, comparison))
    line = check(key, comparison).splitlines()[2]
    column = line.index(comparison.split(": ")[1]) + 1  # the value compared with
    assert problem.startswith(f"tree.yaml:3:{column}: {expected}")


def test_a_check_of_a_touch_against_quoted_true_is_refused_where_it_would_never_succeed(
    tmp_path: Path,
) -> None:
    assert problems_of(tmp_path, check("/sensors/touch/any", 'equals: "true"')) == [
        "tree.yaml:3:48: /sensors/touch/any holds true/false, never 'true' "
        "(write true without quotes)"
    ]


def test_a_check_of_a_variable_may_compare_with_anything(tmp_path: Path) -> None:
    path = write(tmp_path, "tree.yaml", check("/vars/mood", 'equals: "true"'))
    loader = TreeLoader(default_registry(), default_catalogue(), root_dir=tmp_path)
    assert loader.load(path).root.children[0].args["equals"] == "true"


def test_a_check_of_a_touch_against_true_without_quotes_thanks_the_toucher(
    tmp_path: Path,
) -> None:
    robot = TreeHarness.from_file(
        write(tmp_path, "tree.yaml", check("/sensors/touch/any", "equals: true"))
    )
    robot.set("/sensors/touch/any", True)
    robot.tick()
    assert robot.said == ["ok"]


# -- keys with characters py_trees cannot read back ------------------------------------------
def test_a_key_with_a_dot_is_refused_with_a_better_name(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Sequence:
            - SetValue: {key: /vars/step.count, value: 1}
            - Check: {key: /vars/step.count, equals: 1}
        """,
    ) == [
        "tree.yaml:3:23: blackboard key '/vars/step.count' has '.': keys use only letters, "
        "digits, '_' and '/' (e.g. '/vars/step_count')",
        "tree.yaml:4:20: blackboard key '/vars/step.count' has '.': keys use only letters, "
        "digits, '_' and '/' (e.g. '/vars/step_count')",
    ]


def test_a_template_field_with_a_dot_in_its_key_is_refused(tmp_path: Path) -> None:
    [problem] = problems_of(tmp_path, 'root:\n  Say: {text: "step {/vars/step.count}"}\n')
    assert problem.startswith("tree.yaml:2:15: blackboard key '/vars/step.count' has '.'")


@pytest.mark.parametrize("key", ["/vars/my-note", "/vars/note 2", "/vars/café", "/devices/*/ok"])
def test_a_key_with_other_characters_is_refused(tmp_path: Path, key: str) -> None:
    [problem] = problems_of(tmp_path, f'root:\n  Check: {{key: "{key}", equals: 1}}\n')
    assert "keys use only letters, digits, '_' and '/'" in problem


# -- item: on a key that is not a list --------------------------------------------------------
def test_item_on_a_key_that_is_not_a_list_is_refused(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path, "root:\n  Check: {key: /sensors/force/left_n, above: 3, item: 0}\n"
    ) == ["tree.yaml:2:55: /sensors/force/left_n holds a number, not a list (remove item:)"]


def test_item_on_a_variable_holding_no_list_fails_the_check_without_an_error(
    tmp_path: Path,
) -> None:
    robot = TreeHarness.from_file(
        write(tmp_path, "tree.yaml", check("/vars/pads", "equals: true, item: 1"))
    )
    robot.set("/vars/pads", "not a list")
    # Check: FAILURE (feedback says why) -> the tree: FAILURE, every tick, no node error
    assert robot.tick(3).name == "FAILURE"
    assert robot.node_errors == []
    assert (
        robot.tree.root.children[0].feedback_message == "/vars/pads holds 'not a list', not a list"
    )


# -- OnEvent on a variable ---------------------------------------------------------------------
def test_on_event_on_a_variable_is_refused_because_it_could_never_fire(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Sequence:
            - SetValue: {key: /vars/go, value: 1}
            - OnEvent: {key: /vars/go}
            - Say: {text: go}
        """,
    ) == [
        "tree.yaml:4:22: '/vars/go' is a tree variable, not an event key "
        "(use Check to compare a /vars/ value each tick)"
    ]


# -- template format specs ---------------------------------------------------------------------
@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("{temperature_f:zz}", "bad format 'zz' in {temperature_f:zz} for a number"),
        ("{temperature_f:d}", "bad format 'd' in {temperature_f:d} for a number"),
        ("{/sensors/touch/any:.1q}", "bad format '.1q' in {/sensors/touch/any:.1q} for a bool"),
    ],
)
def test_a_template_format_that_cannot_format_the_value_is_refused_at_load(
    tmp_path: Path, text: str, expected: str
) -> None:
    [problem] = problems_of(tmp_path, f'root:\n  Say: {{text: "It is {text}"}}\n')
    assert problem.startswith(f"tree.yaml:2:15: {expected}")


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("{temperature_f:.0f}", "It is 72"),
        ("{temperature_f:>6.1f}", "It is   71.9"),
        ("{/vars/x:.2f}", "It is 1.50"),
    ],
)
def test_a_template_format_that_suits_the_value_loads_and_fills(
    tmp_path: Path, text: str, said: str
) -> None:
    path = write(tmp_path, "tree.yaml", f'root:\n  Say: {{text: "It is {text}"}}\n')
    robot = TreeHarness.from_file(path)
    robot.set("/sensors/temperature/f", 71.94)
    robot.set("/vars/x", 1.5)
    robot.tick()
    assert robot.said == [said]


def test_a_dialog_answer_with_a_bad_format_is_refused_at_its_place(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "dialogs/d.yaml",
        """\
        dialog: d
        rules:
          - hear: [hi]
            say: "{temperature_f:zz}"
        """,
    )
    with pytest.raises(LoadError) as caught:
        load_dialog(path, default_catalogue(), "d.yaml")
    [problem] = [str(p) for p in caught.value.problems]
    assert problem.startswith("d.yaml:4:10: bad format 'zz' in {temperature_f:zz} for a number")
