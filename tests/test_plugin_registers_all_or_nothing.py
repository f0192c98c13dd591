"""A plugin's register() adds all of its node types or, when one fails, none of them."""

from __future__ import annotations

from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

from engine.nodes.registry import ENTRY_POINT_GROUP, builtin_registry

HALF_CLASHING_PLUGIN = '''
from engine.nodes import Condition


class Fine(Condition):
    """A good node."""

    def check(self):
        return True


class Say(Condition):
    """Clashes with the built-in Say."""

    def check(self):
        return True


def register(registry):
    registry.add(Fine)
    registry.add(Say)


def register_twice(registry):
    registry.add(Fine)
    registry.add(Fine)


def register_then_crash(registry):
    registry.add(Fine)
    raise RuntimeError("the LED driver is missing")
'''


@pytest.fixture
def plugin_on_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "half_vest_plugin.py").write_text(HALF_CLASHING_PLUGIN, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))


def load(function: str) -> tuple[list[str], bool]:
    """Load ``half_vest_plugin:function``: the registry's plugin errors, and whether Fine
    got in."""
    registry = builtin_registry()
    registry.load_plugins(
        [EntryPoint(name="half", value=f"half_vest_plugin:{function}", group=ENTRY_POINT_GROUP)]
    )
    return registry.plugin_errors, "Fine" in registry


def test_a_plugin_whose_second_node_clashes_leaves_its_first_node_out(
    plugin_on_path: None,
) -> None:
    errors, fine_registered = load("register")
    assert errors == [
        "plugin half (half_vest_plugin:register): node type 'Say' from "
        "half_vest_plugin:register is already registered by vest"
    ]
    assert not fine_registered


def test_a_plugin_registering_one_name_twice_leaves_it_out(plugin_on_path: None) -> None:
    errors, fine_registered = load("register_twice")
    assert errors == [
        "plugin half (half_vest_plugin:register_twice): node type 'Fine' is registered "
        "twice by half_vest_plugin:register_twice"
    ]
    assert not fine_registered


def test_a_plugin_crashing_after_adding_a_node_leaves_it_out(plugin_on_path: None) -> None:
    errors, fine_registered = load("register_then_crash")
    assert errors == [
        "plugin half (half_vest_plugin:register_then_crash): the LED driver is missing"
    ]
    assert not fine_registered
