"""Two YAML readers, one answer: libyaml's fast one for good files and the careful one
that words problems give the same values and places; what the fast one cannot word goes
to the careful one; lone surrogates are refused with their place; a huge tree validates."""

from __future__ import annotations

from pathlib import Path

import pytest

import engine.files.yaml_events as yaml_events
from engine.cli import main
from engine.files.problems import LoadError
from engine.files.yaml_events import NeedsCarefulReading, compose_fast
from engine.files.yaml_source import MAX_DEPTH, MAX_NODES, YList, YMap, YValue, parse_yaml

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = sorted(
    path for folder in ("trees", "dialogs", "examples") for path in (ROOT / folder).rglob("*.yaml")
)


def fast(text: str) -> YValue | None:
    return compose_fast(text, "f.yaml", max_nodes=MAX_NODES, max_depth=MAX_DEPTH)


def careful(text: str, monkeypatch: pytest.MonkeyPatch) -> YValue | None:
    with monkeypatch.context() as patched:
        patched.setattr(yaml_events, "PARSER", None)
        return parse_yaml(text, "f.yaml")


def places(value: YValue | None) -> object:
    """The value with every place, as comparable data."""
    if isinstance(value, YMap):
        return (
            "map",
            value.mark,
            [(key, value.key_marks[key], places(item)) for key, item in value.items()],
        )
    if isinstance(value, YList):
        return ("list", value.mark, [places(item) for item in value])
    return None if value is None else ("scalar", value.mark, repr(value.value))


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(ROOT)))
def test_both_readers_read_every_shipped_file_alike(
    path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    text = path.read_text()
    assert places(fast(text)) == places(careful(text, monkeypatch))


@pytest.mark.parametrize(
    "text",
    [
        "a: &x {b: 1, c: [1, 2.5, true, null, 2024-01-02]}\nd: *x\ne: *x\n",
        "'quoted key': \"esc\\u00e9\"\nplain: |\n  block\n  text\n",
        "",
        "- 0x1F\n- 1_000\n- .inf\n- -.nan\n- ~\n- 'yes'\n",
    ],
)
def test_both_readers_agree_on_aliases_styles_and_scalars(
    text: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert places(fast(text)) == places(careful(text, monkeypatch))


@pytest.mark.parametrize(
    "text",
    [
        "a: 1\na: 2\n",  # a duplicate key
        "a: !!python/object:os.system x\n",  # a refused tag
        "<<: {a: 1}\n",  # a merge
        "a: &x [*x]\n",  # an alias inside its own anchor
        "a: " + "[" * (MAX_DEPTH + 5) + "]" * (MAX_DEPTH + 5) + "\n",  # too deep
        "a: 1\n---\nb: 2\n",  # two documents
        "a: 1" + "0" * 5000 + "\n",  # an integer Python will not convert
        'a: "\\uD800"\n',  # a lone surrogate
        "a: b: c\n",  # a syntax error
    ],
)
def test_what_the_fast_reader_cannot_word_goes_to_the_careful_one(text: str) -> None:
    with pytest.raises(NeedsCarefulReading):
        fast(text)


def test_flow_nesting_far_past_the_limit_is_refused_without_parsing_it_all() -> None:
    deep = "[" * 500_000 + "]" * 500_000  # libyaml takes minutes on the whole of this
    with pytest.raises(LoadError, match="nested more than 100 levels"):
        parse_yaml(deep, "deep.yaml")


@pytest.mark.parametrize(
    ("text", "place"),
    [
        ('name: "caf\\uD800e"\n', "s.yaml:1:7"),
        ('"\\uDFFFkey": 1\n', "s.yaml:1:1"),
        ('say:\n  - text: "hi \\udc80"\n', "s.yaml:2:11"),
    ],
)
def test_a_lone_surrogate_escape_is_refused_with_its_place(text: str, place: str) -> None:
    with pytest.raises(LoadError) as caught:
        parse_yaml(text, "s.yaml")
    [problem] = caught.value.problems
    assert str(problem).startswith(f"{place}: \\u")
    assert "half of a character pair" in problem.message


def test_a_tree_named_with_a_lone_surrogate_is_refused_by_validate_run_and_render(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = tmp_path / "odd.yaml"
    tree.write_text('name: "odd\\uD800"\nrate_hz: 10\nroot:\n  Say: {text: hi}\n')
    for command in (["validate", str(tree)], ["render", str(tree)]):
        assert main(command) == 1
        assert "half of a character pair" in capsys.readouterr().err


def test_a_ten_thousand_node_tree_validates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lines = ["name: big", "rate_hz: 10", "root:", "  Sequence:"]
    for i in range(5000):
        lines.append("    - Check: {key: /sensors/touch/any, equals: true}")
        lines.append(f'    - Say: {{text: "hello {i}"}}')
    (tmp_path / "big.yaml").write_text("\n".join(lines) + "\n")
    assert main(["validate", str(tmp_path / "big.yaml")]) == 0
    assert capsys.readouterr().out.strip() == "ok: 1 file"
