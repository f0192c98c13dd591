"""Bad tree files: every problem is reported as ``file:line:column: message (hint)``.

Each test writes a small tree the way a therapist might get it wrong and checks the exact
place and the start of the message. Files are named relative to ``tmp_path`` (the loader's
``root_dir``), so a problem reads ``tree.yaml:4:7: ...``.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.files.problems import LoadError
from engine.loader.substitution import Profile, load_profile
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry
from engine.testing import TreeHarness

REPO = Path(__file__).resolve().parents[2]


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def load(folder: Path, path: Path, profile: Profile | None = None) -> TreeDefinition:
    loader = TreeLoader(default_registry(), default_catalogue(), profile=profile, root_dir=folder)
    return loader.load(path)


def problems(folder: Path, path: Path, profile: Profile | None = None) -> list[str]:
    """Every problem of the tree at ``path``, as the lines a person would read."""
    with pytest.raises(LoadError) as caught:
        load(folder, path, profile)
    lines = [str(problem) for problem in caught.value.problems]
    assert str(caught.value).splitlines() == lines
    return lines


def problems_of(folder: Path, text: str) -> list[str]:
    return problems(folder, write(folder, "tree.yaml", text))


# -- node types and parameters -------------------------------------------------------------
def test_an_unknown_node_type_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        name: thanks
        root:
          Sequence:
            - Chek: {key: /sensors/touch/any, equals: true}
            - Say: {text: "Thank you"}
        """,
    ) == ["tree.yaml:4:7: unknown node type 'Chek' (did you mean 'Check'?)"]


def test_an_unknown_parameter_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Say: {text: hello, volum: 0.5}
        """,
    ) == ["tree.yaml:2:22: unknown parameter 'volum' for Say (did you mean 'volume'?)"]


def test_a_misspelled_required_parameter_is_named(tmp_path: Path) -> None:
    assert "tree.yaml:2:9: unknown parameter 'txt' for Say (did you mean 'text'?)" in problems_of(
        tmp_path,
        """\
        root:
          Say: {txt: hello}
        """,
    )


def test_a_word_where_a_number_belongs_is_named_with_its_value(tmp_path: Path) -> None:
    [problem] = problems_of(
        tmp_path,
        """\
        root:
          Check: {key: /sensors/force/left_n, above: three}
        """,
    )
    assert problem.startswith("tree.yaml:2:46: 'above' must be a number, got 'three'")


def test_not_a_number_is_no_threshold(tmp_path: Path) -> None:
    [problem] = problems_of(
        tmp_path,
        """\
        root:
          Check: {key: /sensors/force/left_n, above: .nan}
        """,
    )
    assert problem.startswith("tree.yaml:2:46: 'above' must be a")


def test_an_unknown_color_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          SetLed: {color: pinkk}
        """,
    ) == [
        "tree.yaml:2:19: unknown color 'pinkk' (did you mean 'pink'? "
        "colors: off, black, white, red, green, blue, yellow, orange, pink, purple, cyan, "
        "magenta, warm_white, or #RRGGBB)"
    ]


# -- blackboard keys -------------------------------------------------------------------------
def test_an_unknown_blackboard_key_suggests_the_nearest_known_key(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Check: {key: /sensors/force/left, above: 3.0}
        """,
    ) == [
        "tree.yaml:2:16: unknown blackboard key '/sensors/force/left' "
        "(did you mean '/sensors/force/left_n'?)"
    ]


def test_an_event_key_checked_like_a_value_points_to_on_event(tmp_path: Path) -> None:
    [problem] = problems_of(
        tmp_path,
        """\
        root:
          Check: {key: /sensors/gesture/last, equals: wave}
        """,
    )
    assert problem.startswith("tree.yaml:2:16: '/sensors/gesture/last' is an event key")
    assert "use OnEvent" in problem


def test_a_value_key_waited_on_as_an_event_points_to_check(tmp_path: Path) -> None:
    [problem] = problems_of(
        tmp_path,
        """\
        root:
          OnEvent: {key: /sensors/touch/any}
        """,
    )
    assert problem.startswith("tree.yaml:2:18: '/sensors/touch/any' is not an event key")
    assert "use Check" in problem


# -- children --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("root", "expected"),
    [
        ("Sequence: []", "tree.yaml:2:13: Sequence needs a list of at least one child"),
        ("Selector:", "tree.yaml:2:3: Selector needs a list of at least one child"),
        ("Cooldown: {seconds: 2}", "tree.yaml:2:3: Cooldown needs 'child:' with one node"),
        (
            "Cooldown: {seconds: 2, child: [{Say: {text: a}}, {Say: {text: b}}]}",
            "tree.yaml:2:33: Cooldown takes one child, got a list of 2 (wrap them in a Sequence)",
        ),
        (
            "Say: {text: hi, child: {Wait: {seconds: 1}}}",
            "tree.yaml:2:19: unknown parameter 'child' for Say",
        ),
    ],
)
def test_wrong_child_counts_are_named(tmp_path: Path, root: str, expected: str) -> None:
    [problem] = problems_of(tmp_path, f"root:\n  {root}\n")
    assert problem.startswith(expected)


def test_a_decorator_given_a_list_of_children_is_told_to_wrap_them(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Cooldown:
            seconds: 2
            child:
              - Say: {text: a}
              - Say: {text: b}
        """,
    ) == ["tree.yaml:5:7: Cooldown takes one child, got a list of 2 (wrap them in a Sequence)"]


# -- subtrees and files ----------------------------------------------------------------------
def test_a_subtree_include_cycle_is_shown_as_a_chain(tmp_path: Path) -> None:
    a = write(tmp_path, "a.yaml", "root:\n  Subtree: {file: b.yaml}\n")
    write(tmp_path, "b.yaml", "root:\n  Subtree: {file: a.yaml}\n")
    [problem] = problems(tmp_path, a)
    assert problem.startswith("b.yaml:2:19: subtree include cycle: a.yaml -> b.yaml -> a.yaml")


def test_a_tree_including_itself_is_a_cycle(tmp_path: Path) -> None:
    [problem] = problems_of(tmp_path, "root:\n  Subtree: {file: tree.yaml}\n")
    assert problem.startswith("tree.yaml:2:19: subtree include cycle: tree.yaml -> tree.yaml")


def test_a_missing_subtree_file_is_named_where_it_is_included(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Subtree: {file: parts/nope.yaml}
        """,
    ) == [
        "parts/nope.yaml:1:1: file not found (check the path)",
        "tree.yaml:2:19: cannot include 'parts/nope.yaml'",
    ]


def test_a_subtree_parameter_it_does_not_declare_suggests_the_nearest(tmp_path: Path) -> None:
    write(
        tmp_path,
        "parts/greet.yaml",
        """\
        params:
          phrase: Hello
        root:
          Say: {text: "${phrase}"}
        """,
    )
    assert problems_of(
        tmp_path,
        """\
        root:
          Subtree: {file: parts/greet.yaml, params: {phrse: Hi}}
        """,
    ) == ["tree.yaml:2:53: Subtree passes unknown parameter 'phrse' (did you mean 'phrase'?)"]


def test_a_part_that_must_be_heard_out_keeps_its_own_sentences_whole(tmp_path: Path) -> None:
    # interruptible: false in a part holds for its sentences, not the including tree's;
    # a sentence that says its own keeps it
    write(
        tmp_path,
        "parts/exercise.yaml",
        """\
        interruptible: false
        root:
          Sequence:
            - Say: {text: "Breathe in slowly"}
            - Say: {text: "Any questions?", interruptible: true}
        """,
    )
    tree = write(
        tmp_path,
        "tree.yaml",
        """\
        root:
          Sequence:
            - Subtree: {file: parts/exercise.yaml}
            - Say: {text: "Well done"}
        """,
    )
    says = [n for n in load(tmp_path, tree).root.walk() if n.type.name == "Say"]
    assert [(n.args["text"].source, n.args["interruptible"]) for n in says] == [
        ("Breathe in slowly", False),
        ("Any questions?", True),
        ("Well done", None),  # as the tree says: true unless it sets otherwise
    ]


def test_a_part_s_interruptible_that_is_no_yes_or_no_is_named(tmp_path: Path) -> None:
    write(tmp_path, "parts/p.yaml", 'interruptible: sometimes\nroot:\n  Say: {text: "Hi"}\n')
    [problem] = problems_of(tmp_path, "root:\n  Subtree: {file: parts/p.yaml}\n")
    assert problem.startswith("parts/p.yaml:1:16: 'interruptible' must be")


def test_a_missing_tree_file_is_named(tmp_path: Path) -> None:
    assert problems(tmp_path, tmp_path / "nope.yaml") == [
        "nope.yaml:1:1: file not found (check the path)"
    ]


def test_the_harness_reports_a_missing_tree_file_too(tmp_path: Path) -> None:
    with pytest.raises(LoadError) as caught:
        TreeHarness.from_file(tmp_path / "nope.yaml")
    assert str(caught.value).startswith(f"{tmp_path / 'nope.yaml'}:1:1: file not found")


# -- YAML itself -----------------------------------------------------------------------------
def test_a_yaml_indentation_error_names_the_line(tmp_path: Path) -> None:
    [problem] = problems_of(
        tmp_path,
        """\
        root:
          Sequence:
            - Say: {text: hi}
           - Say: {text: ho}
        """,
    )
    assert problem.startswith("tree.yaml:4:4: YAML syntax error: expected <block end>")
    assert "check the indentation" in problem


def test_a_colon_inside_unquoted_text_suggests_quotes(tmp_path: Path) -> None:
    [problem] = problems_of(
        tmp_path,
        """\
        root:
          Say:
            text: Note: be kind
        """,
    )
    assert problem.startswith("tree.yaml:3:15: YAML syntax error: mapping values are not allowed")
    assert "put text containing ': ' in quotes" in problem


def test_a_tab_in_the_indentation_is_named(tmp_path: Path) -> None:
    path = tmp_path / "tree.yaml"
    path.write_text("root:\n  Sequence:\n  \t- Say: {text: hi}\n", encoding="utf-8")
    [problem] = problems(tmp_path, path)
    assert problem.startswith("tree.yaml:3:3: YAML syntax error: found character '\\t'")
    assert "indent with spaces, not tabs" in problem


def test_a_control_character_is_named_at_its_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "tree.yaml"
    path.write_text("root:\n  Say: {text: hi}\n  \x0c\n", encoding="utf-8")
    [problem] = problems(tmp_path, path)
    assert problem.startswith("tree.yaml:3:3: ")


def test_a_byte_that_is_not_utf8_is_named_at_its_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "tree.yaml"
    path.write_bytes(b"name: greet\nroot:\n  Say: {text: caf\xe9}\n")  # Latin-1 e-acute
    assert problems(tmp_path, path) == [
        "tree.yaml:3:18: byte 0xE9 is not UTF-8 text (save the file as UTF-8)"
    ]


def test_a_file_over_one_mebibyte_is_refused_unread(tmp_path: Path) -> None:
    path = tmp_path / "tree.yaml"
    path.write_bytes(b"# padding\n" * 150_000 + b"root:\n  Say: {text: hi}\n")
    [problem] = problems(tmp_path, path)
    assert problem.startswith("tree.yaml:1:1: file is ")
    assert "more than the 1024 KiB" in problem


def test_a_duplicate_key_names_both_lines(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        name: hug
        rate_hz: 20
        name: big_hug
        root:
          Say: {text: hi}
        """,
    ) == ["tree.yaml:3:1: duplicate key 'name' (first at line 1) (keep only one)"]


def test_a_duplicate_parameter_in_a_flow_mapping_is_named(tmp_path: Path) -> None:
    [problem] = problems_of(tmp_path, "root:\n  Say: {text: hi, text: ho}\n")
    assert problem.startswith("tree.yaml:2:19: duplicate key 'text' (first at line 2)")


@pytest.mark.parametrize("tag", ["!!python/object/apply:os.mkdir", "!!python/object/new:os.mkdir"])
def test_python_tags_are_refused_and_never_run(tmp_path: Path, tag: str) -> None:
    marker = tmp_path / "pwned"
    [problem] = problems_of(tmp_path, f"root:\n  Say: {{text: {tag} ['{marker}']}}\n")
    assert problem.startswith(f"tree.yaml:2:15: YAML tag '{tag}' is not allowed")
    assert not marker.exists()


def test_python_names_are_refused(tmp_path: Path) -> None:
    [problem] = problems_of(tmp_path, "root:\n  Say: {text: !!python/name:os.system ''}\n")
    assert problem.startswith("tree.yaml:2:15: YAML tag '!!python/name:os.system' is not allowed")


def test_a_billion_laughs_of_aliases_is_stopped(tmp_path: Path) -> None:
    lines = ['lol0: &lol0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for level in range(1, 9):
        aliases = ", ".join([f"*lol{level - 1}"] * 9)
        lines.append(f"lol{level}: &lol{level} [{aliases}]")
    lines.append("root:\n  Say: {text: hi}")
    path = tmp_path / "tree.yaml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    [problem] = problems(tmp_path, path)
    assert re.match(r"tree\.yaml:1:\d+: file expands to more than 100000 values", problem)


# -- parameters and profiles ----------------------------------------------------------------
@pytest.mark.parametrize(
    ("use", "column"),
    [
        ('Say: {text: "${phrse}"}', 15),
        ('Say: {text: "Hi ${phrse}!"}', 15),
        ('Check: {key: /sensors/force/left_n, above: "${phrse}"}', 46),
    ],
)
def test_an_unknown_parameter_reference_suggests_the_nearest_and_nothing_else(
    tmp_path: Path, use: str, column: int
) -> None:
    assert problems_of(tmp_path, f"params:\n  phrase: hi\nroot:\n  {use}\n") == [
        f"tree.yaml:4:{column}: unknown parameter ${{phrse}} (did you mean 'phrase'?)"
    ]


def test_a_profile_value_of_the_wrong_kind_points_at_the_profile(tmp_path: Path) -> None:
    tree = write(
        tmp_path,
        "tree.yaml",
        """\
        params:
          rest_s: 3.0
        root:
          Cooldown:
            seconds: ${rest_s}
            child:
              Say: {text: hi}
        """,
    )
    write(tmp_path, "profiles/kid.yaml", "profile: kid\nparams:\n  rest_s: soon\n")
    profile = load_profile(tmp_path / "profiles/kid.yaml", "profiles/kid.yaml")
    assert problems(tmp_path, tree, profile) == [
        "profiles/kid.yaml:3:11: profile 'kid' sets 'rest_s' to 'soon', but the tree expects "
        "number (default at line 2)"
    ]


def test_a_profile_substitutes_values_keeping_their_type(tmp_path: Path) -> None:
    profile = load_profile(REPO / "trees" / "profiles" / "child.yaml")
    hug = load(REPO, REPO / "trees" / "hug.yaml", profile)
    left, _right, cooldown = hug.root.children
    set_led, say = cooldown.children[0].children
    assert left.args["above"] == 2.0 and isinstance(left.args["above"], float)
    assert cooldown.args["seconds"] == 5.0
    assert say.args["volume"] == 0.6
    assert str(say.args["text"]) == "Yay, a big hug!"
    assert set_led.args["color"] == "pink"


def test_a_parameter_inside_longer_text_becomes_text(tmp_path: Path) -> None:
    tree = load(
        tmp_path,
        write(
            tmp_path,
            "tree.yaml",
            """\
        params:
          times: 3
        root:
          Say: {text: "I hugged you ${times} times"}
        """,
        ),
    )
    assert str(tree.root.args["text"]) == "I hugged you 3 times"


# -- the file as a whole --------------------------------------------------------------------
def test_every_problem_of_a_file_is_reported_together(tmp_path: Path) -> None:
    lines = problems_of(
        tmp_path,
        """\
        name: session
        rate_hz: 20
        root:
          Sequence:
            - Chek: {key: /sensors/touch/any, equals: true}
            - SetLed: {color: pinkk}
            - Wait: {seconds: long}
            - Check: {key: /sensors/force/left, above: 3.0}
        """,
    )
    assert [line.split(": ", 1)[0] for line in lines] == [
        "tree.yaml:5:7",
        "tree.yaml:6:23",
        "tree.yaml:7:23",
        "tree.yaml:8:20",
    ]


@pytest.mark.parametrize(
    ("rate", "expected"),
    [
        ("0", "'rate_hz' must be at least 0.1, got 0"),
        ("-5", "'rate_hz' must be at least 0.1, got -5"),
        ("5.0e-324", "'rate_hz' must be at least 0.1, got 4.94066e-324"),  # a period of inf
        ("5000", "'rate_hz' must be at most 1000, got 5000"),
        (".inf", "'rate_hz' must be a finite number, got inf"),
        ("fast", "'rate_hz' must be a number, got 'fast'"),
    ],
)
def test_a_tick_rate_out_of_range_is_named(tmp_path: Path, rate: str, expected: str) -> None:
    [problem] = problems_of(tmp_path, f"rate_hz: {rate}\nroot:\n  Say: {{text: hi}}\n")
    assert problem.startswith(f"tree.yaml:1:10: {expected}")


def test_an_unknown_template_field_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        root:
          Say: {text: "It is {temperatur_f:.0f} degrees"}
        """,
    ) == ["tree.yaml:2:15: unknown template field {temperatur_f} (did you mean 'temperature_f'?)"]


def test_an_unknown_top_level_field_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems_of(
        tmp_path,
        """\
        name: hug
        rate: 20
        root:
          Say: {text: hi}
        """,
    ) == ["tree.yaml:2:1: unknown field 'rate' (did you mean 'rate_hz'?)"]


def test_a_parameter_of_the_wrong_type_is_shown_where_it_was_written_and_named(
    tmp_path: Path,
) -> None:
    assert problems_of(
        tmp_path,
        """\
        params:
          force_n: three
        root:
          Check: {key: /sensors/force/left_n, above: "${force_n}"}
        """,
    ) == [
        "tree.yaml:2:12: parameter 'force_n' is used as Check.above (tree.yaml:4:46): "
        "'above' must be a number, got 'three' (write digits, e.g. 3.0)"
    ]


def test_a_profile_value_of_the_wrong_type_is_shown_in_the_profile(tmp_path: Path) -> None:
    profile_file = write(tmp_path, "kid.yaml", "profile: kid\nparams:\n  force_n: lots\n")
    tree = write(
        tmp_path,
        "tree.yaml",
        'params:\n  force_n: three\nroot:\n  Say: {text: hi, volume: "${force_n}"}\n',
    )
    loader = TreeLoader(
        default_registry(),
        default_catalogue(),
        root_dir=tmp_path,
        profile=load_profile(profile_file, "kid.yaml"),
    )
    with pytest.raises(LoadError) as caught:
        loader.load(tree)
    assert [str(p) for p in caught.value.problems] == [
        "kid.yaml:3:12: parameter 'force_n' is used as Say.volume (tree.yaml:4:27): "
        "'volume' must be a number, got 'lots' (write digits, e.g. 3.0)"
    ]
