"""The editor's palette: every node a tree may use, from the same declarations as
``vest nodes`` (a plugin's nodes too), each parameter as a form field that knows its type,
unit, range and choices, and the robot's own words: its pads, joints and colours."""

from __future__ import annotations

from typing import Any

from engine.blackboard.catalogue import KeyCatalogue
from engine.colors import NAMED_COLORS
from engine.hardware.config import RobotConfig
from engine.loader.tree_drawing import PLAIN_WORDS
from engine.loader.tree_settings import SETTINGS as TREE_SETTINGS
from engine.nodes.registry import NodeRegistry
from engine.values.params import (
    REQUIRED,
    Boolean,
    Choice,
    Integer,
    Key,
    ListOf,
    Number,
    Param,
    ParamType,
    Text,
)
from engine.values.templates import Template

VOCABULARY = {"pads": "pads", "except_pads": "pads", "joint": "joints", "color": "colors"}
"""Parameters whose values are the robot's own words: pad names, joints, colours."""
KINDS_IN_WORDS = {
    "condition": "questions (yes or no)",
    "action": "things the robot does",
    "composite": "how the nodes under it run",
    "decorator": "rules for the node under it",
}


def palette(
    registry: NodeRegistry, config: RobotConfig | None, catalogue: KeyCatalogue
) -> dict[str, Any]:
    """What the page offers: nodes grouped by kind, and the words its forms choose from."""
    nodes = [
        {
            "name": node.name,
            "kind": node.kind,
            "summary": " ".join(_plain_doc(node.doc).split("\n\n", 1)[0].split()),
            "doc": _plain_doc(node.doc),
            "children": node.children,
            "source": node.source,
            "words": PLAIN_WORDS.get(node.name),
            "params": [field_of(param) for param in node.params],
        }
        for node in sorted(registry, key=lambda n: n.name)
    ]
    nodes.append(
        {
            "name": "Subtree",
            "kind": "action",
            "summary": "Include another tree file's behaviour (a part).",
            "doc": "Include another tree file's root, with its params set here.",
            "children": "none",
            "source": "vest",
            "params": [
                {"name": "file", "kind": "text", "required": True, "doc": "e.g. parts/greet.yaml"},
                {"name": "params", "kind": "any", "required": False, "doc": "its params"},
            ],
        }
    )
    devices = config.devices.values() if config is not None else []
    return {
        "kinds": KINDS_IN_WORDS,
        "settings": [field_of(setting) for setting in TREE_SETTINGS],
        "nodes": nodes,
        "pads": [name for device in devices for name in device.pad_names],
        "joints": [joint.name for device in devices for joint in device.joints],
        "colors": list(NAMED_COLORS),
        "keys": sorted(spec.name for spec in catalogue if not spec.is_pattern),
    }


def field_of(param: Param[Any]) -> dict[str, Any]:
    """One parameter as a form field."""
    field: dict[str, Any] = {
        "name": param.name,
        "doc": _plain_doc(param.doc),
        "required": param.default is REQUIRED,
        **_type_of(param.type),
    }
    if param.default is not REQUIRED and param.default is not None:
        field["default"] = param.default
    words = VOCABULARY.get(param.name)
    if words is not None:
        field["words"] = words
    return field


def _type_of(kind: ParamType[Any]) -> dict[str, Any]:
    if isinstance(kind, Number | Integer):
        found: dict[str, Any] = {"kind": "integer" if isinstance(kind, Integer) else "number"}
        if kind.minimum is not None:
            found["min"] = kind.minimum
        if kind.maximum is not None:
            found["max"] = kind.maximum
        unit = getattr(kind, "unit", "")
        if unit:
            found["unit"] = unit
        return found
    if isinstance(kind, Boolean):
        return {"kind": "boolean"}
    if isinstance(kind, Choice):
        return {"kind": "choice", "options": list(kind.options)}
    if isinstance(kind, Key):
        return {"kind": "key", "access": kind.access}
    if isinstance(kind, ListOf):
        return {"kind": "list", "item": _type_of(kind.item)}
    if isinstance(kind, Text | Template):
        return {"kind": "text", "describe": kind.describe()}
    return {"kind": "any", "describe": kind.describe()}  # a number, a word or a list


def _plain_doc(doc: str) -> str:
    """A docstring as a person reads it: without reStructuredText's ``double quotes``."""
    return doc.strip().replace("``", "")
