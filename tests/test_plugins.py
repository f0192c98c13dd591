"""Plugins: node types from other packages, found through the "vest.nodes" entry points.

The example package in examples/plugin is put on sys.path, and its entry points are built
here as ``importlib.metadata.EntryPoint`` objects, the same objects vest gets from an
installed package's metadata.
"""

from __future__ import annotations

import itertools
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any

import py_trees
import pytest
from py_trees.common import Status

from engine.blackboard.catalogue import KeySpec
from engine.files.problems import LoadError
from engine.nodes.base import Condition
from engine.nodes.docs import nodes_json, nodes_markdown
from engine.nodes.registry import (
    ENTRY_POINT_GROUP,
    NodeRegistry,
    builtin_registry,
    default_registry,
)
from engine.testing import TreeHarness

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "plugin"
WARM_GREETING = EXAMPLE / "trees" / "warm_greeting.yaml"


def entry(name: str, value: str) -> EntryPoint:
    return EntryPoint(name=name, value=value, group=ENTRY_POINT_GROUP)


REGISTER_ENTRY = entry("example-nodes", "vest_example_nodes:register")
IS_WARM_ENTRY = entry("IsWarm", "vest_example_nodes:IsWarm")


@pytest.fixture
def example_on_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """The example plugin importable, as if installed."""
    monkeypatch.syspath_prepend(str(EXAMPLE))


@pytest.fixture
def registry(example_on_path: None) -> NodeRegistry:
    """The built-in nodes plus the example plugin, loaded through its register function."""
    registry = builtin_registry()
    registry.load_plugins(entries=[REGISTER_ENTRY])
    assert registry.plugin_errors == []
    return registry


# -- appearing in the registry ----------------------------------------------------------


def test_a_register_function_entry_point_adds_every_node_it_registers(
    registry: NodeRegistry,
) -> None:
    assert "IsWarm" in registry
    assert "Blink" in registry
    assert registry.get("IsWarm").kind == "condition"
    assert registry.get("Blink").kind == "action"
    # without package metadata, the entry point's target names the source
    assert registry.get("Blink").source == "vest_example_nodes:register"


def test_a_class_entry_point_adds_that_one_node(example_on_path: None) -> None:
    registry = builtin_registry()
    registry.load_plugins(entries=[IS_WARM_ENTRY])

    assert registry.plugin_errors == []
    assert "IsWarm" in registry
    assert "Blink" not in registry
    assert registry.get("IsWarm").source == "vest_example_nodes:IsWarm"


def test_plugin_nodes_are_listed_with_their_parameters_and_source(
    registry: NodeRegistry,
) -> None:
    listed = {node["name"]: node for node in nodes_json(registry)}
    blink = listed["Blink"]
    assert [p["name"] for p in blink["params"]] == ["color", "times", "on_s", "off_s"]
    assert blink["params"][1] == {
        "name": "times",
        "type": "integer 1..20",
        "required": False,
        "default": 3,
        "doc": "how many flashes",
    }
    assert listed["IsWarm"]["reads"] == ["/sensors/temperature/c"]

    page = nodes_markdown(registry)
    assert "### IsWarm" in page
    assert "From: vest_example_nodes:register" in page


# -- used in YAML -------------------------------------------------------------------------


def test_warm_greeting_blinks_and_mentions_the_warmth_on_a_warm_day(
    registry: NodeRegistry,
) -> None:
    robot = TreeHarness.from_file(WARM_GREETING, registry=registry)
    robot.world.temperature_c = 28.0

    robot.set("/sensors/gesture/last", "wave")
    robot.advance(2.0)

    # one reading, one phrase, three orange flashes: 0.3 s lit then 0.3 s dark, seen by
    # ticks 0.1 s apart, so the next flash starts 0.6 to 0.7 s after the last one
    assert robot.did("read") == [{"sensor": "temperature"}]
    assert robot.said == ["Hello! What a warm day."]
    assert robot.did("led") == [{"color": "orange", "seconds": 0.3}] * 3
    flashes_s = [record.t for record in robot.actions if record.action == "led"]
    assert all(0.6 - 1e-9 <= b - a <= 0.7 + 1e-9 for a, b in itertools.pairwise(flashes_s))


def test_warm_greeting_just_says_hello_on_a_cool_day(registry: NodeRegistry) -> None:
    robot = TreeHarness.from_file(WARM_GREETING, registry=registry)
    robot.world.temperature_c = 19.0

    robot.set("/sensors/gesture/last", "wave")
    robot.advance(2.0)

    assert robot.did("led") == []
    assert robot.said == ["Hello!"]


def test_blink_turns_the_leds_off_when_a_higher_priority_branch_takes_over(
    registry: NodeRegistry, tmp_path: Path
) -> None:
    tree = tmp_path / "attention.yaml"
    tree.write_text(
        "name: attention\n"
        "rate_hz: 10\n"
        "root:\n"
        "  Selector:\n"
        "    - Sequence:\n"
        "        - Check: {key: /sensors/touch/any, equals: true}\n"
        '        - Say: {text: "You found me!"}\n'
        "    - Blink: {color: blue, times: 10}\n",
        encoding="utf-8",
    )
    robot = TreeHarness.from_file(tree, registry=registry)

    robot.advance(0.2)  # blinking blue, waiting for a touch
    assert robot.did("led") == [{"color": "blue", "seconds": 0.3}]
    robot.set("/sensors/touch/any", True)
    robot.tick()

    assert robot.said == ["You found me!"]
    assert robot.did("led")[-1] == {"color": "off"}


def test_a_plugin_node_with_a_wrong_parameter_is_a_file_line_column_problem(
    registry: NodeRegistry, tmp_path: Path
) -> None:
    tree = tmp_path / "blinky.yaml"
    tree.write_text("name: blinky\nroot:\n  Blink: {color: pinkish, times: 50}\n")

    with pytest.raises(LoadError) as raised:
        TreeHarness.from_file(tree, registry=registry)

    assert [str(problem) for problem in raised.value.problems] == [
        f"{tree}:3:18: unknown color 'pinkish' (did you mean 'pink'? "
        "colors: off, black, white, red, green, blue, yellow, orange, pink, purple, cyan, "
        "magenta, warm_white, or #RRGGBB)",
        f"{tree}:3:34: 'times' must be at most 20, got 50",
    ]


# -- broken plugins and clashes -----------------------------------------------------------

BROKEN_PLUGIN = '''
"""Plugins that cannot work, one way each."""


def register(registry):
    raise RuntimeError("the LED driver is missing")


def register_nothing(registry):
    pass


NOT_A_NODE = 42
'''

CLASHING_PLUGIN = '''
from engine.nodes import Condition


class Say(Condition):
    """A condition that wants the built-in action's name."""

    def check(self):
        return True
'''


def test_a_broken_plugin_is_reported_without_stopping_the_others(
    example_on_path: None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "broken_vest_plugin.py").write_text(BROKEN_PLUGIN, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = builtin_registry()

    registry.load_plugins(
        entries=[
            entry("missing", "no_such_vest_plugin:Thing"),
            entry("crashing", "broken_vest_plugin:register"),
            entry("empty", "broken_vest_plugin:register_nothing"),
            entry("number", "broken_vest_plugin:NOT_A_NODE"),
            REGISTER_ENTRY,
        ]
    )

    assert "IsWarm" in registry and "Blink" in registry
    assert "Say" in registry  # the built-in nodes are all still there
    assert registry.plugin_errors == [
        "plugin missing (no_such_vest_plugin:Thing): No module named 'no_such_vest_plugin'",
        "plugin crashing (broken_vest_plugin:register): the LED driver is missing",
        "plugin empty (broken_vest_plugin:register_nothing): registered no node type and no key",
        "plugin number (broken_vest_plugin:NOT_A_NODE): "
        "is neither a Leaf subclass nor a register(registry) function",
    ]


def test_a_node_name_taken_by_another_plugin_names_both_sources(example_on_path: None) -> None:
    registry = builtin_registry()

    registry.load_plugins(entries=[REGISTER_ENTRY, IS_WARM_ENTRY])

    assert registry.plugin_errors == [
        "plugin IsWarm (vest_example_nodes:IsWarm): node type 'IsWarm' from "
        "vest_example_nodes:IsWarm is already registered by vest_example_nodes:register"
    ]
    assert registry.get("IsWarm").source == "vest_example_nodes:register"


def test_a_plugin_cannot_replace_a_built_in_node(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "clashing_vest_plugin.py").write_text(CLASHING_PLUGIN, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = builtin_registry()

    registry.load_plugins(entries=[entry("Say", "clashing_vest_plugin:Say")])

    assert registry.plugin_errors == [
        "plugin Say (clashing_vest_plugin:Say): node type 'Say' from clashing_vest_plugin:Say "
        "is already registered by vest"
    ]
    assert registry.get("Say").kind == "action"


# -- the generated reference --------------------------------------------------------------


def test_docs_nodes_md_is_the_generated_node_reference() -> None:
    expected = nodes_markdown(default_registry(plugins=False))
    written = (REPO / "docs" / "nodes.md").read_text(encoding="utf-8")

    assert written == expected, (
        "docs/nodes.md is out of date with the node declarations: regenerate it with "
        "`.venv/bin/vest nodes --format md > docs/nodes.md` (with no plugin package installed)"
    )


class Greeter(Condition):
    """SUCCESS when the plugin's own doorbell service says someone is at the door."""

    def __init__(self, name: str, args: Any, ctx: Any, *, doorbell: list[str]) -> None:
        super().__init__(name, args, ctx)
        self.doorbell = doorbell

    def check(self) -> bool:
        return bool(self.doorbell)


def test_a_plugin_node_gets_its_own_service_bound_at_registration(tmp_path: Path) -> None:
    doorbell: list[str] = []
    registry = builtin_registry()
    registry.add(Greeter, doorbell=doorbell)
    tree = tmp_path / "door.yaml"
    tree.write_text("rate_hz: 10\nroot:\n  Greeter: {}\n")
    robot = TreeHarness.from_file(tree, registry=registry)
    assert robot.tick() == Status.FAILURE
    doorbell.append("ding")
    assert robot.tick() == Status.SUCCESS


def test_binding_a_service_the_node_does_not_take_is_refused_in_words() -> None:
    with pytest.raises(TypeError, match=r"Greeter cannot take speaker"):
        builtin_registry().add(Greeter, speaker=object())


def test_a_plain_py_trees_behaviour_is_refused_in_words() -> None:
    with pytest.raises(TypeError, match=r"Success is a plain py_trees behaviour: subclass"):
        builtin_registry().add(py_trees.behaviours.Success)  # type: ignore[arg-type]


DOORBELL_PLUGIN = """
import py_trees

from engine.blackboard.catalogue import KeySpec
from engine.nodes.spec import NodeType


def _twice(name, args, children, ctx):
    return py_trees.decorators.Repeat(name=name, child=children[0], num_success=2)


def register(registry):
    registry.add_key(KeySpec("/sensors/doorbell/ringing", bool, "", "doorbell plugin", "rung"))
    registry.add(NodeType("Twice", "decorator", "Do the child twice.", (), _twice))
"""


def test_a_plugin_adds_a_decorator_and_its_sensor_s_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "doorbell_vest_plugin.py").write_text(DOORBELL_PLUGIN, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = builtin_registry()
    registry.load_plugins(entries=[entry("doorbell", "doorbell_vest_plugin:register")])
    assert registry.plugin_errors == []
    tree = tmp_path / "door.yaml"
    tree.write_text(
        "rate_hz: 10\nroot:\n  Sequence:\n"
        "    - Check: {key: /sensors/doorbell/ringing, equals: true}\n"
        "    - Twice: {child: {Say: {text: Coming!}}}\n"
    )
    robot = TreeHarness.from_file(tree, registry=registry)
    robot.set("/sensors/doorbell/ringing", True)
    robot.advance(5.0)
    assert robot.said[:2] == ["Coming!", "Coming!"]
    assert registry.catalogue().lookup("/sensors/doorbell/ringing") is not None


def test_a_plugin_key_that_already_exists_is_refused() -> None:
    with pytest.raises(ValueError, match="already exists"):
        builtin_registry().add_key(KeySpec("/sensors/touch/any", bool, "", "me", "mine"))
