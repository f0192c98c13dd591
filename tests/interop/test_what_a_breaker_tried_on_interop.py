"""What someone trying to break the doors to other tools tried, each now refused by name
or kept exact: a small XML that expands to millions of nodes, a SubTree ID that would write
YAML, texts that read back as other values, a leaf with children, a description that would
add a key, very deep nesting, names XML cannot carry, two trees with one ID, a damaged
recording converted."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import pytest
import yaml

from engine.cli import main

ROOT = Path(__file__).resolve().parents[2]


def xml_file(tmp_path: Path, body: str, name: str = "t.xml") -> Path:
    path = tmp_path / name
    path.write_text(f'<root BTCPP_format="4" main_tree_to_execute="T">\n{body}\n</root>\n')
    return path


def imported(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(["import", str(path)])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_small_file_that_expands_to_millions_of_nodes_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    trees = [f'<BehaviorTree ID="T{n}"><Sequence><SubTree ID="T{n + 1}"/><SubTree ID="T{n + 1}"/>'
             f"</Sequence></BehaviorTree>" for n in range(22)]  # fmt: skip
    trees.append('<BehaviorTree ID="T22"><OnTouch/></BehaviorTree>')
    path = xml_file(tmp_path, "\n".join(trees).replace('ID="T0"', 'ID="T"', 1))
    code, _, err = imported(path, capsys)
    assert code == 1 and "is over 5000 nodes" in err


def test_very_deep_nesting_is_named_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    deep = "<Inverter>" * 500 + "<OnTouch/>" + "</Inverter>" * 500
    code, _, err = imported(
        xml_file(tmp_path, f'<BehaviorTree ID="T">{deep}</BehaviorTree>'), capsys
    )
    assert code == 1 and "deeper than 200" in err and "Traceback" not in err


def test_a_subtree_id_cannot_write_yaml_and_two_trees_cannot_share_an_id(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    sneaky = "P&#10;    - Say: {text: INJECTED}"
    body = (
        f'<BehaviorTree ID="T"><Sequence><SubTree ID="{sneaky}"/></Sequence></BehaviorTree>'
        f'<BehaviorTree ID="{sneaky}"><OnTouch/></BehaviorTree>'
    )
    code, out, _ = imported(xml_file(tmp_path, body), capsys)
    assert code == 0 and "INJECTED" not in yaml.safe_dump(yaml.safe_load(out))
    twice = (
        '<BehaviorTree ID="T"><OnTouch/></BehaviorTree><BehaviorTree ID="T"><Say/></BehaviorTree>'
    )
    code, _, err = imported(xml_file(tmp_path, twice, "twice.xml"), capsys)
    assert code == 1 and "a second BehaviorTree with ID 'T'" in err


def test_a_leaf_with_children_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    body = '<BehaviorTree ID="T"><Say text="hi"><Say text="lost child"/></Say></BehaviorTree>'
    code, _, err = imported(xml_file(tmp_path, body), capsys)
    assert code == 1 and "<Say> takes no children" in err


def test_texts_that_look_like_other_values_and_names_xml_cannot_carry_come_back_exact(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    (tmp_path / "trees").mkdir()
    shutil.copytree(ROOT / "dialogs", tmp_path / "dialogs")
    tree = tmp_path / "trees" / "odd---name.yaml"
    tree.write_text(
        "name: odd\nrate_hz: 5\npriority: 7\n"
        'description: "Greets people.\\u2028priority: 90"\n'
        "root:\n  Sequence:\n"
        '    - Check: {key: /vars/answer, equals: "yes"}\n'
        '    - Check: {key: /vars/answer, equals: "0x1F"}\n'
        '    - Check: {key: /vars/answer, equals: "007"}\n'
        '    - Check: {key: /vars/answer, equals: "true"}\n'
        '    - Say: {name: "bell\\a here", text: "ring \\a -- <now>"}\n'
        "    - Timeout: {seconds: 0.0004, child: {Wait: {seconds: 1}}}\n"
    )
    xml = tmp_path / "odd.xml"
    assert main(["export", str(tree), "--format", "btcpp", "-o", str(xml)]) == 0
    back = tmp_path / "trees" / "back.yaml"
    assert main(["import", str(xml), "-o", str(back)]) == 0
    loaded = yaml.safe_load(back.read_text())
    assert loaded["priority"] == 7 and loaded["rate_hz"] == 5
    assert loaded["description"] == "Greets people.\u2028priority: 90"
    children = loaded["root"]["Sequence"]
    assert [c["Check"]["equals"] for c in children[:4]] == ["yes", "0x1F", "007", "true"]
    assert children[4]["Say"]["text"] == "ring \a -- <now>"
    assert children[5]["Timeout"]["seconds"] == 0.0004


def test_a_damaged_recording_converts_to_nothing_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    old = tmp_path / "old.db"
    shutil.copy(ROOT / "tests/recordings/unplug_touch.format1.db", old)
    with sqlite3.connect(old) as db:
        db.execute(
            "UPDATE statuses SET at_s = 1e300 "
            "WHERE rowid = (SELECT min(rowid) FROM statuses WHERE tree = 'hug')"
        )
    for kind in ("mcap", "btlog"):
        args = ["replay", str(old), "--to", kind, "-o", str(tmp_path / f"s.{kind}")]
        assert main([*args, "--tree", "hug"] if kind == "btlog" else args) == 1
        assert "a damaged recording" in capsys.readouterr().err
        assert not (tmp_path / f"s.{kind}").exists()
