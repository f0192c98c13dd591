"""A lab's trees travel between vest and BehaviorTree.CPP: every shipped tree is written as
BehaviorTree.CPP v4 XML that BehaviorTree.CPP's own factory builds (through behaviortreepy,
our node types registered as stand-ins), read back into YAML that validates and behaves
the same on the shipped scenarios, and what has no counterpart is named, never guessed."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import behaviortreepy as btcpp
import pytest

from engine.cli import main
from engine.cli.run_inputs import load_tree
from engine.interop.btcpp_export import btcpp_xml

ROOT = Path(__file__).resolve().parents[2]
TREES = sorted((ROOT / "trees").glob("*.yaml"))
SCENARIOS = sorted((ROOT / "examples" / "scenarios").glob("*.yaml"))


def exported(tree: Path) -> str:
    definition, registry = load_tree(tree, None)
    return btcpp_xml(definition, registry)


def stand_ins(document: ET.Element) -> tuple[btcpp.BehaviorTreeFactory, dict[str, set[str]]]:
    """A factory with each node type of the model registered as a stand-in (the bindings
    take no ports for a Python node), and the ports the model declares for each."""
    factory = btcpp.BehaviorTreeFactory()
    ports: dict[str, set[str]] = {}
    model = document.find("TreeNodesModel")
    assert model is not None
    for entry in model:
        node_id = entry.attrib["ID"]
        ports[node_id] = {port.attrib["name"] for port in entry.findall("input_port")}
        if entry.tag in ("Action", "Condition"):
            factory.register_simple_action(node_id, lambda node: btcpp.NodeStatus.SUCCESS)
        elif entry.tag == "Decorator":
            factory.register_simple_decorator(node_id, lambda status, node: status)
    return factory, ports


@pytest.mark.parametrize("tree", TREES, ids=[tree.stem for tree in TREES])
def test_behaviortree_cpp_builds_every_shipped_tree(tree: Path) -> None:
    document = ET.fromstring(exported(tree))
    assert document.attrib["BTCPP_format"] == "4"
    factory, ports = stand_ins(document)
    for element in document.iter():
        if element.tag in ports:  # ours: every port it is given is in the model
            given = set(element.attrib) - {"name"}
            assert given <= ports[element.tag], (element.tag, given - ports[element.tag])
            element.attrib = {k: v for k, v in element.attrib.items() if k == "name"}
    built = factory.create_tree_from_text(ET.tostring(document, encoding="unicode"))
    assert built.root_node() is not None  # their nodes with their real ports, checked


def test_the_finger_game_s_rounds_are_subtrees_each_filled_in(tmp_path: Path) -> None:
    document = ET.fromstring(exported(ROOT / "trees" / "finger_game.yaml"))
    ids = [tree.attrib["ID"] for tree in document.findall("BehaviorTree")]
    assert ids == ["finger_game", "finger_round", "finger_round_2", "finger_round_3"]
    assert document.attrib["main_tree_to_execute"] == "finger_game"
    says = [e.attrib["text"] for e in document.findall("BehaviorTree[2]//Say")]
    assert says[0] == "Show me three fingers!"


def run_json(trees: Path, scenario: Path, capsys: pytest.CaptureFixture[str]) -> list[dict]:
    args = ["run", "--fast", "--speech", "text", "--json", "--scenario", str(scenario)]
    assert main([*args, "--trees", *sorted(str(t) for t in trees.glob("*.yaml"))]) == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines() if line]


def test_exported_and_imported_back_every_tree_behaves_the_same_on_every_scenario(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(ROOT)
    again = tmp_path / "trees"
    again.mkdir()
    for tree in TREES:
        xml = tmp_path / f"{tree.stem}.xml"
        assert main(["export", str(tree), "--format", "btcpp", "-o", str(xml)]) == 0
        assert main(["import", str(xml), "-o", str(again / tree.name)]) == 0
    capsys.readouterr()
    assert main(["validate", str(again), "dialogs/"]) == 0
    capsys.readouterr()
    for scenario in SCENARIOS:
        before = run_json(ROOT / "trees", scenario, capsys)
        after = run_json(again, scenario, capsys)
        assert len(before) > 5 and after == before, scenario.name


def test_what_vest_has_no_counterpart_for_is_named_with_its_place(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    theirs = tmp_path / "theirs.xml"
    theirs.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="T">\n'
        '  <BehaviorTree ID="T">\n'
        "    <Sequence>\n"
        '      <Script code="x := 1"/>\n'
        '      <Check key="{target}" above="1"/>\n'
        '      <SubTree ID="Sub" target="{pose}"/>\n'
        '      <Say text="hi" _skipIf="x == 1"/>\n'
        '      <ParallelAll max_failures="2"><Say text="a"/></ParallelAll>\n'
        "    </Sequence>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    out = tmp_path / "t.yaml"
    assert main(["import", str(theirs), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    for expected in (
        r'theirs.xml:4:7: <Script code="x := 1">: vest has no node that means the same',
        r"theirs.xml:5:7: <Check> key='\{target\}': blackboard remapping, which vest lacks",
        r"theirs.xml:6:7: <SubTree ID='Sub'> port target: vest's subtrees take no ports",
        r"theirs.xml:7:7: <Say> _skipIf: vest has no pre/post conditions",
        r'theirs.xml:8:7: <ParallelAll max_failures="2">: vest has no node that means the same',
    ):
        assert re.search(expected, err), (expected, err)
    assert not out.exists()


def test_a_bt_cpp_tree_using_what_vest_has_becomes_yaml_with_where_it_came_from(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    theirs = tmp_path / "greet.xml"
    theirs.write_text(
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="greet">\n'
        "    <ReactiveFallback>\n"
        '      <SubTree ID="wave"/>\n'
        '      <Timeout msec="1500"><Say text="Hello!" volume="0.5"/></Timeout>\n'
        "    </ReactiveFallback>\n"
        "  </BehaviorTree>\n"
        '  <BehaviorTree ID="wave"><OnEvent key="/sensors/gesture/last"/></BehaviorTree>\n'
        "</root>\n"
    )
    assert main(["import", str(theirs)]) == 0
    text = capsys.readouterr().out
    assert "# imported by vest from" in text and '# SubTree "wave" (line 4)' in text
    assert "rate_hz: 10.0   # BehaviorTree.CPP trees have no rate of their own" in text
    assert "- Timeout:\n        seconds: 1.5\n        child:\n          Say: {text: Hello!" in text


def test_an_imported_tree_that_vest_validate_refuses_is_not_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    theirs = tmp_path / "t.xml"
    theirs.write_text(
        '<root BTCPP_format="4">\n  <BehaviorTree ID="t"><Check key="/nope/x" above="1"/>'
        "</BehaviorTree>\n</root>\n"
    )
    out = tmp_path / "t.yaml"
    assert main(["import", str(theirs), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "does not pass vest validate" in err and "unknown blackboard key '/nope/x'" in err
    assert f"({theirs} as YAML):" in err and not out.exists()


def test_a_text_that_fills_in_a_key_and_the_explicit_form_of_a_node_come_through(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    theirs = tmp_path / "pad.xml"
    theirs.write_text(
        '<root BTCPP_format="4">\n  <BehaviorTree ID="pad">\n    <Sequence>\n'
        '      <Action ID="OnTouch" _description="as Groot2 writes it"/>\n'
        '      <Say text="You touched {/sensors/touch/touched}"/>\n'
        "    </Sequence>\n  </BehaviorTree>\n</root>\n"
    )
    assert main(["import", str(theirs)]) == 0
    captured = capsys.readouterr()
    assert "- OnTouch: {}" in captured.out
    assert "Say: {text: 'You touched {/sensors/touch/touched}'}" in captured.out
    assert "no vest settings (_vest_settings" in captured.err  # not made by vest: said
