"""A JSON Schema of tree files, made from the node declarations (``vest schema``).

Editors use it for completion and squiggles while a tree is typed (VS Code's YAML
extension: ``# yaml-language-server: $schema=tree.schema.json`` at the top of a file).
It is a help, not the judge: ``vest validate`` checks more (blackboard keys, templates,
subtrees, cross-parameter rules) and says where and how to fix it.
"""

from __future__ import annotations

from typing import Any

from engine.nodes.registry import NodeRegistry
from engine.nodes.spec import NodeType

# any parameter may be given as ${name}, replaced before the value is checked
_PARAMETER_REFERENCE = {"type": "string", "pattern": r"^\$\{[^}]+\}$"}
_NODE = {"$ref": "#/$defs/node"}


def _value(schema: dict[str, Any]) -> dict[str, Any]:
    return {"anyOf": [schema, _PARAMETER_REFERENCE]} if schema else {}


def _body(node_type: NodeType) -> dict[str, Any]:
    properties: dict[str, Any] = {"name": {"type": "string", "description": "display name"}}
    for param in node_type.params:
        properties[param.name] = {**_value(param.type.json_schema()), "description": param.doc}
    required = [p.name for p in node_type.params if p.required]
    if node_type.children == "many":
        properties["children"] = {"type": "array", "items": _NODE, "minItems": 1}
        required.append("children")
    elif node_type.children == "one":
        properties["child"] = _NODE
        required.append("child")
    body: dict[str, Any] = {
        "type": "object",
        "properties": properties,
        "additionalProperties": False,
    }
    if required:
        body["required"] = required
    if node_type.children == "many":
        return {"anyOf": [{"type": "array", "items": _NODE, "minItems": 1}, body]}
    if not required:
        return {"anyOf": [body, {"type": "null"}]}
    return body


def tree_schema(registry: NodeRegistry) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a vest tree file."""
    nodes = [
        {
            "type": "object",
            "properties": {t.name: {**_body(t), "description": t.summary}},
            "required": [t.name],
            "additionalProperties": False,
        }
        for t in registry
    ]
    nodes.append(
        {
            "type": "object",
            "properties": {
                "Subtree": {
                    "type": "object",
                    "properties": {
                        "file": {"type": "string", "description": "tree file to include"},
                        "params": {"type": "object", "description": "its parameters"},
                        "name": {"type": "string"},
                    },
                    "required": ["file"],
                    "additionalProperties": False,
                    "description": "Include another tree file's root here.",
                }
            },
            "required": ["Subtree"],
            "additionalProperties": False,
        }
    )
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "vest behavior tree",
        "type": "object",
        "properties": {
            "name": {"type": "string"},
            "description": {"type": "string"},
            "rate_hz": _value({"type": "number", "exclusiveMinimum": 0, "maximum": 1000}),
            "priority": _value({"type": "integer", "minimum": 0, "maximum": 99}),
            "wait_for_turn_s": _value({"type": "number", "minimum": 0, "maximum": 60}),
            "when_interrupted": _value({"enum": ["let_go", "try_again"]}),
            "wake_on": {
                "type": "array",
                "items": {"type": "string", "pattern": "^/"},
                "maxItems": 32,
                "description": "blackboard keys whose change wakes the tree",
            },
            "params": {"type": "object", "description": "parameters used as ${name}"},
            "root": _NODE,
        },
        "required": ["root"],
        "additionalProperties": False,
        "$defs": {"node": {"oneOf": nodes}},
    }
