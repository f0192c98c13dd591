"""A vest tree as BehaviorTree.CPP v4 XML (``vest export TREE --format btcpp``), which
Groot2 opens and draws and BehaviorTree.CPP's factory builds.

Where our node means what a BehaviorTree.CPP node means (engine/nodes/bt_cpp_counterparts.py,
tested tick by tick against BehaviorTree.CPP), it is written as that node with its ports:
``Sequence`` as ``Sequence`` or ``ReactiveSequence``, ``Selector`` as ``ReactiveFallback``
or ``Fallback``, ``Parallel`` as ``ParallelAll`` or ``Parallel``, ``Repeat``,
``RetryUntilSuccessful``, ``Timeout`` (msec), ``RunOnce``, ``Inverter``, ``ForceSuccess``.
Every other node (our leaves, ``Cooldown``, ``OneShot`` after success, ``Parallel`` with
synchronise: false) is written as our own node type, declared with its ports in the
``TreeNodesModel`` (all of our leaves, so Groot2's palette has them). A subtree is a
``SubTree``; its parameters are already filled in (BehaviorTree.CPP has none), so each
differently filled use is a BehaviorTree of its own (``finger_round``, ``finger_round_2``).
The tree's rate, priority and turn settings are the main BehaviorTree's ``_vest_settings``
attribute (JSON), which BehaviorTree.CPP ignores and ``vest import`` reads.

A port's value is its text: numbers as written (``3.0``), true/false, and lists as
``json:[...]`` (BehaviorTree.CPP v4's prefix for JSON). Defaults are left out.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any
from xml.sax.saxutils import quoteattr

from engine.loader.tree_definition import NodeDefinition, TreeDefinition
from engine.nodes.registry import NodeRegistry
from engine.nodes.spec import NodeType
from engine.values.templates import CompiledTemplate

BTCPP_FORMAT = "4"
SETTINGS_ATTRIBUTE = "_vest_settings"
"""The main BehaviorTree's attribute holding the tree's rate, priority and turns (JSON)."""
_MODEL_TAGS = {"action": "Action", "condition": "Condition", "decorator": "Decorator"}
_MODEL_TAGS["composite"] = "Control"


def port_text(value: Any) -> str:
    """A parameter's value as BehaviorTree.CPP reads a port: text. A text that would read
    back as another kind of value (``"true"``, ``"7"``) or holds a character XML cannot
    carry is written as JSON (``json:"7"``), so ``vest import`` gives back the same."""
    if isinstance(value, CompiledTemplate):
        return _text_port(value.source)
    if isinstance(value, str):
        return _text_port(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple | dict):
        return "json:" + json.dumps(value, ensure_ascii=False, separators=(",", ":"))
    if isinstance(value, float):
        return repr(value)
    return str(value)


def btcpp_node(node: NodeDefinition) -> tuple[str, dict[str, str]]:
    """The BehaviorTree.CPP node ``node`` is written as, and its ports (our own node type
    with its parameters when BehaviorTree.CPP has no node that means the same)."""
    kind, args = node.type.name, node.args
    if kind == "Sequence":
        return ("Sequence" if args.get("memory", True) else "ReactiveSequence"), {}
    if kind == "Selector":
        return ("Fallback" if args.get("memory", False) else "ReactiveFallback"), {}
    if kind == "Parallel" and args.get("synchronise", True):
        if args.get("succeed_when", "all") == "one":
            return "Parallel", {"success_count": "1", "failure_count": "-1"}
        return "ParallelAll", {"max_failures": "1"}
    if kind in ("Inverter", "ForceSuccess"):
        return kind, {}
    if kind == "Repeat":
        return "Repeat", {"num_cycles": str(args["times"])}
    if kind == "Retry":
        return "RetryUntilSuccessful", {"num_attempts": str(args["times"])}
    if kind == "Timeout" and _whole_msec(float(args["seconds"])):
        return "Timeout", {"msec": str(round(float(args["seconds"]) * 1000))}
    if kind == "OneShot" and args.get("after") == "completion":
        return "RunOnce", {"then_skip": "false"}
    return own_id(node.type), own_ports(node)


def _whole_msec(seconds: float) -> bool:
    """Whether BehaviorTree.CPP's ``msec`` carries ``seconds`` exactly (else: our own)."""
    msec = seconds * 1000
    return msec >= 1 and abs(msec - round(msec)) < 1e-6


LOOKS_TYPED = re.compile(r"true|false|-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?|json:.*", re.S)
NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff\ud800-\udfff]")
"""Characters XML 1.0 cannot carry, even escaped."""


def _text_port(text: str) -> str:
    if LOOKS_TYPED.fullmatch(text) or NOT_XML.search(text):
        return "json:" + json.dumps(text, ensure_ascii=False).replace("\u2028", "\\u2028")
    return text


def xml_safe(text: str) -> str:
    """``text`` with what XML cannot carry replaced (a name, a label, a comment)."""
    return NOT_XML.sub("\ufffd", text)


def own_id(node_type: NodeType) -> str:
    """Our node type's ID in BehaviorTree.CPP: its name, or ``Vest<name>`` where that
    name is one of BehaviorTree.CPP's own nodes (our ``Parallel`` with synchronise: false)."""
    return f"Vest{node_type.name}" if node_type.name in BTCPP_BUILTINS else node_type.name


def own_ports(node: NodeDefinition) -> dict[str, str]:
    ports: dict[str, str] = {}
    for param in node.type.params:
        value = node.args.get(param.name)
        if value is None or (not param.required and value == param.default):
            continue
        ports[param.name] = port_text(value)
    return ports


BTCPP_BUILTINS = frozenset(
    {
        "Sequence", "SequenceWithMemory", "ReactiveSequence", "Fallback", "ReactiveFallback",
        "Parallel", "ParallelAll", "IfThenElse", "WhileDoElse", "Switch2", "Switch3",
        "Switch4", "Switch5", "Switch6", "Inverter", "ForceSuccess", "ForceFailure",
        "Repeat", "RetryUntilSuccessful", "KeepRunningUntilFailure", "Timeout", "Delay",
        "RunOnce", "Precondition", "AlwaysSuccess", "AlwaysFailure", "Script",
        "ScriptCondition", "SetBlackboard", "Sleep", "SubTree", "UnsetBlackboard",
        "WasEntryUpdated", "SkipUnlessUpdated", "WaitValueUpdate", "LoopInt", "LoopDouble",
        "LoopString", "LoopBool", "EntryUpdated",
    }
)  # fmt: skip
"""BehaviorTree.CPP v4's own node IDs (an ID of ours may not take one)."""


ALWAYS_THEIRS = frozenset({"Sequence", "Selector", "Inverter", "ForceSuccess", "Repeat"})
ALWAYS_THEIRS |= {"Retry", "Timeout"}
"""Our node types always written as BehaviorTree.CPP's own (never in the model)."""


@dataclass
class _Writer:
    trees: dict[str, str] = field(default_factory=dict)
    """BehaviorTree ID -> its body (XML), the main tree first."""

    def tree_id(self, name: str, body: str) -> str:
        """The ID of the BehaviorTree whose body is ``body`` (one made for it if new)."""
        for tree_id, known in self.trees.items():
            if known == body and (tree_id == name or tree_id.startswith(f"{name}_")):
                return tree_id
        tree_id, number = name, 1
        while tree_id in self.trees:
            number += 1
            tree_id = f"{name}_{number}"
        self.trees[tree_id] = body
        return tree_id

    def element(self, node: NodeDefinition, depth: int, top: bool = False) -> str:
        indent = "  " * depth
        if node.subtree is not None and not top:
            body = self.element(node, 2, top=True)
            tree_id = self.tree_id(_stem(node.subtree), body)
            return f"{indent}<SubTree ID={quoteattr(tree_id)}/>\n"
        tag, ports = btcpp_node(node)
        attributes = "".join(f" {name}={quoteattr(text)}" for name, text in ports.items())
        if node.name != node.type.name:
            attributes = f" name={quoteattr(xml_safe(node.name))}" + attributes
        if not node.children:
            return f"{indent}<{tag}{attributes}/>\n"
        inner = "".join(self.element(child, depth + 1) for child in node.children)
        return f"{indent}<{tag}{attributes}>\n{inner}{indent}</{tag}>\n"


def _stem(file: str) -> str:
    name = file.replace("\\", "/").rsplit("/", 1)[-1]
    return name.rsplit(".", 1)[0] or "subtree"


def btcpp_xml(definition: TreeDefinition, registry: NodeRegistry) -> str:
    """The tree as BehaviorTree.CPP v4 XML: ``main_tree_to_execute`` is the tree's name,
    each subtree a BehaviorTree of its own, then the model of every node type of ours in
    ``registry`` (the palette Groot2 shows) with its ports."""
    writer = _Writer()
    writer.trees[definition.name] = ""  # the main tree keeps its own name
    settings = {
        "rate_hz": definition.rate_hz,
        "priority": definition.priority,
        "wait_for_turn_s": definition.wait_for_turn_s,
        "when_interrupted": definition.when_interrupted,
        "wake_on": list(definition.wake_on),
        "description": definition.description.strip(),
    }
    writer.trees[definition.name] = writer.element(definition.root, 2, top=True)
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>\n',
        f'<root BTCPP_format="{BTCPP_FORMAT}" main_tree_to_execute={quoteattr(definition.name)}>\n',
        f"  <!-- {_comment(definition)} -->\n",
    ]
    for tree_id, body in writer.trees.items():
        kept = ""  # BehaviorTree.CPP ignores an attribute of a BehaviorTree it does not know
        if tree_id == definition.name:
            kept = f" {SETTINGS_ATTRIBUTE}={quoteattr(json.dumps(settings, ensure_ascii=False))}"
        parts.append(f"  <BehaviorTree ID={quoteattr(tree_id)}{kept}>\n{body}  </BehaviorTree>\n")
    parts.append("  <TreeNodesModel>\n")
    parts.extend(model_entries(registry))
    parts.append("  </TreeNodesModel>\n</root>\n")
    return "".join(parts)


def _comment(definition: TreeDefinition) -> str:
    text = xml_safe(f"exported by vest from {definition.path.name}; vest import reads it back")
    while "--" in text:  # a comment cannot hold two dashes
        text = text.replace("--", "- -")
    return text.rstrip("-")


def model_entries(registry: Iterable[NodeType]) -> list[str]:
    """``<Action ID=...><input_port name=... default=...>doc</input_port></Action>`` for
    each of our node types BehaviorTree.CPP has no node for."""
    entries = []
    for node_type in registry:
        if node_type.name in ALWAYS_THEIRS:
            continue
        tag = _MODEL_TAGS[node_type.kind]
        ports = []
        for param in node_type.params:
            default = "" if param.required else f" default={quoteattr(port_text(param.default))}"
            if param.default is None:
                default = ""
            doc = (param.doc or "").replace("\n", " ")
            ports.append(
                f"      <input_port name={quoteattr(param.name)}{default}>"
                f"{_text(doc)}</input_port>\n"
            )
        entries.append(
            f"    <{tag} ID={quoteattr(own_id(node_type))}>\n" + "".join(ports) + f"    </{tag}>\n"
        )
    return entries


def _text(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
