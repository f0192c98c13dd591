"""The common YAML slips a therapist makes are named at the line of the mistake, in plain
words, with what to write instead (not where PyYAML got stuck, lines later)."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.cli import main

CHECK = "    - Check: {key: /sensors/touch/any, equals: true}\n"


def told(tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str) -> str:
    path = tmp_path / "tree.yaml"
    path.write_text("name: t\nroot:\n  Sequence:\n" + body)
    assert main(["validate", str(path)]) == 1
    [line, _count] = capsys.readouterr().err.splitlines()
    return line.removeprefix(f"{path}:")


def test_an_apostrophe_inside_single_quotes(tmp_path, capsys):
    line = told(tmp_path, capsys, CHECK + "    - Say: {text: 'That's funny!'}\n")
    assert line.startswith("5:19: the text in single quotes ends at the apostrophe")
    assert "write text with an apostrophe in double quotes" in line


def test_a_child_without_its_dash(tmp_path, capsys):
    line = told(tmp_path, capsys, CHECK + '    Say: {text: "hi"}\n')
    assert line.startswith("5:5: this line is not a list item like the ones above it")
    assert "start it with '- '" in line


def test_a_node_without_its_colon_before_its_settings(tmp_path, capsys):
    line = told(tmp_path, capsys, CHECK + '    - Say {text: "hi"}\n')
    assert line == "5:7: 'Say' needs a colon after it (write Say: {...})"


def test_a_composite_without_its_colon(tmp_path, capsys):
    path = tmp_path / "tree.yaml"
    path.write_text('name: t\nroot:\n  Sequence\n    - Say: {text: "hi"}\n')
    assert main(["validate", str(path)]) == 1
    assert f"{path}:3:3: 'Sequence' needs a colon after it" in capsys.readouterr().err


def test_children_after_options_without_children(tmp_path, capsys):
    line = told(tmp_path, capsys, "    name: greet\n" + CHECK)
    assert line.startswith("5:5: children after a node's options need 'children:'")


def test_a_parameter_indented_too_little(tmp_path, capsys):
    line = told(tmp_path, capsys, '    - Say:\n        text: "hi"\n      volume: 0.8\n')
    assert line == (
        "6:7: 'volume' belongs to Say but is not indented under it "
        "(indent volume: as far as Say's other settings)"
    )


def test_a_quote_left_open_is_named_where_it_opens_not_lines_later(tmp_path, capsys):
    many = "".join(f'    - Say: {{text: "line {n}"}}\n' for n in range(10))
    line = told(tmp_path, capsys, '    - Say:\n        text: "hi\n' + many)
    assert line.startswith("5:15: this quote is not closed on its line")
