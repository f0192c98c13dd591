"""A BehaviorTree.CPP v4 XML tree as our YAML (``vest import FILE.xml``), for a tree that
uses what vest has: BehaviorTree.CPP's nodes that mean what ours mean (the inverse of
:mod:`engine.interop.btcpp_export`), our own node types by ID, and SubTrees (written in
place: our YAML names a subtree by file, BehaviorTree.CPP by ID). What has no counterpart
(Script, SetBlackboard, a Switch, blackboard remapping ``{x}``, SubTree ports, ``_skipIf``
and the other pre/post conditions, thresholds our Parallel lacks) is named with its line
and column, never guessed.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from typing import Any

import yaml

from engine.files.problems import LoadError, Problem, Problems
from engine.interop.btcpp_export import BTCPP_BUILTINS, SETTINGS_ATTRIBUTE, own_id
from engine.interop.xml_places import Element, parse_xml
from engine.nodes.registry import NodeRegistry
from engine.nodes.spec import NodeType
from engine.values.param_problems import did_you_mean
from engine.values.params import Boolean, Integer, ListOf, Number
from engine.values.templates import Template

SETTINGS = (
    "rate_hz",
    "priority",
    "wait_for_turn_s",
    "when_interrupted",
    "wake_on",
    "description",
)
DEFAULT_RATE_HZ = 10.0
MAX_NODES = 5000
MAX_DEPTH = 200
JSON_NUMBER = re.compile(r"-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?")
GENERIC_TAGS = frozenset({"Action", "Condition", "Decorator", "Control"})
"""BehaviorTree.CPP's explicit form of a node: ``<Action ID="Say"/>``."""
METADATA = ("_description", "_uid", "_fullpath", "_autoremap")
"""Attributes Groot2 and BehaviorTree.CPP keep about a node, not what it does."""
COMMENT = "#"
"""A node's note, written as a YAML comment after it (where an inlined subtree came from)."""


@dataclass
class _Importer:
    registry: NodeRegistry
    trees: dict[str, Element]
    problems: Problems = field(default_factory=Problems)
    opening: list[str] = field(default_factory=list)
    expanded: int = 0
    """Nodes made so far (SubTrees written in place: a small file can expand to millions)."""
    too_big: bool = False

    def node(self, element: Element, depth: int = 0) -> dict[str, Any] | None:
        """Our YAML node (``{Type: ...}``) for ``element``; None (a problem noted) when it
        has no counterpart."""
        self.expanded += 1
        if self.expanded > MAX_NODES or depth > MAX_DEPTH:
            if not self.too_big:
                why = f"deeper than {MAX_DEPTH}" if depth > MAX_DEPTH else f"over {MAX_NODES}"
                self.problems.add(
                    element.mark, f"the tree, SubTrees written in place, is {why} nodes"
                )
                self.too_big = True
            return None
        tag, attrs = element.tag, dict(element.attributes)
        if tag in GENERIC_TAGS and "ID" in attrs:  # <Action ID="Say" .../>, as Groot2 writes
            tag = attrs.pop("ID")
            element = Element(tag, attrs, element.mark, element.children)
        name = attrs.pop("name", None)
        for attribute in METADATA:
            attrs.pop(attribute, None)
        for attribute in sorted(attrs):
            if attribute.startswith("_"):
                self.problems.add(
                    element.mark,
                    f"<{tag}> {attribute}: vest has no pre/post conditions on a node",
                    "put the condition in the tree (a Check before it)",
                )
                return None
        if tag == "SubTree":
            return self.subtree(element, attrs, depth, name)
        children = [self.node(child, depth + 1) for child in element.children]
        if any(child is None for child in children):
            return None
        kept = [child for child in children if child is not None]
        if tag in BTCPP_BUILTINS:  # never one of our IDs (own_id)
            mapped = self.theirs(element, attrs, kept)
        else:
            mapped = self.ours(element, attrs, kept)
        if mapped is None:
            return None
        if name is not None:
            ((kind, body),) = mapped.items()
            mapped = {kind: {"name": name, **_as_options(body)}}
        return mapped

    def subtree(
        self, element: Element, attrs: dict[str, str], depth: int, name: str | None
    ) -> dict[str, Any] | None:
        tree_id = attrs.pop("ID", "")
        if attrs:
            port = sorted(attrs)[0]
            self.problems.add(
                element.mark,
                f"<SubTree ID={tree_id!r}> port {port}: vest's subtrees take no ports",
                "write the values into the subtree itself",
            )
            return None
        body = self.trees.get(tree_id)
        if body is None:
            hint = did_you_mean(tree_id, self.trees)
            self.problems.add(element.mark, f"no BehaviorTree with ID {tree_id!r}", hint)
            return None
        if tree_id in self.opening:
            self.problems.add(element.mark, f"SubTree {tree_id!r} includes itself")
            return None
        self.opening.append(tree_id)
        try:
            inlined = self.tree_root(body, depth + 1)
        finally:
            self.opening.pop()
        if inlined is None:
            return None
        shown = json.dumps(tree_id, ensure_ascii=True)  # one line, whatever the ID holds
        if name is not None:  # the SubTree's own name goes to the node in its place
            inner = {k: v for k, v in inlined.items() if k != COMMENT}
            ((kind, body),) = inner.items()
            inlined = {kind: {"name": name, **_as_options(body)}}
        return {COMMENT: f"SubTree {shown} (line {element.mark.line})", **inlined}

    def tree_root(self, tree: Element, depth: int = 0) -> dict[str, Any] | None:
        if len(tree.children) != 1:
            self.problems.add(tree.mark, "a BehaviorTree holds exactly one root node")
            return None
        return self.node(tree.children[0], depth)

    def theirs(
        self, element: Element, attrs: dict[str, str], children: list[dict[str, Any]]
    ) -> dict[str, Any] | None:
        """BehaviorTree.CPP's own node as ours, when one means the same; else None (and
        a problem noted)."""
        tag = element.tag
        composite = {
            "Sequence": ("Sequence", {}),
            "ReactiveSequence": ("Sequence", {"memory": False}),
            "Fallback": ("Selector", {"memory": True}),
            "ReactiveFallback": ("Selector", {}),
        }
        if tag in composite and not attrs:
            kind, options = composite[tag]
            return {kind: {**options, "children": children} if options else children}
        if tag == "ParallelAll" and attrs in ({"max_failures": "1"}, {}):
            return {"Parallel": children}
        if tag == "Parallel" and attrs == {"success_count": "1", "failure_count": "-1"}:
            return {"Parallel": {"succeed_when": "one", "children": children}}
        decorators: dict[str, tuple[str, str | None]] = {
            "Inverter": ("Inverter", None),
            "ForceSuccess": ("ForceSuccess", None),
        }
        decorators |= {"Repeat": ("Repeat", "num_cycles"), "Timeout": ("Timeout", "msec")}
        decorators["RetryUntilSuccessful"] = ("Retry", "num_attempts")
        if tag in decorators and len(children) == 1:
            kind, port = decorators[tag]
            if port is None and not attrs:
                return {kind: {"child": children[0]}}
            if port is not None and set(attrs) == {port}:
                number = _whole(attrs[port])
                if number is None or number <= 0:
                    self.problems.add(element.mark, f"<{tag}> {port}: a whole number above 0")
                    return None
                if kind == "Timeout":
                    return {kind: {"seconds": number / 1000, "child": children[0]}}
                return {kind: {"times": number, "child": children[0]}}
        if tag == "RunOnce" and attrs == {"then_skip": "false"} and len(children) == 1:
            return {"OneShot": {"after": "completion", "child": children[0]}}
        shown = " ".join(f'{k}="{v}"' for k, v in sorted(attrs.items()))
        self.problems.add(
            element.mark,
            f"<{tag}{' ' + shown if shown else ''}>: vest has no node that means the same",
            "docs/interop.md lists what vest writes and reads",
        )
        return None

    def ours(
        self, element: Element, attrs: dict[str, str], children: list[dict[str, Any]]
    ) -> dict[str, Any] | None:
        node_type = self.node_type(element.tag)
        if node_type is None:
            names = [own_id(t) for t in self.registry]
            hint = did_you_mean(element.tag, names)
            self.problems.add(element.mark, f"<{element.tag}>: no such node in vest", hint)
            return None
        args: dict[str, Any] = {}
        for port, text in attrs.items():
            param = node_type.param(port)
            if param is None:
                hint = did_you_mean(port, [p.name for p in node_type.params])
                self.problems.add(element.mark, f"<{element.tag}> has no port {port!r}", hint)
                continue
            remapped = re.fullmatch(r"\{[^{}]*\}", text.strip())
            if remapped and not isinstance(param.type, Template):  # in a text: our {key}
                self.problems.add(
                    element.mark,
                    f"<{element.tag}> {port}={text!r}: blackboard remapping, which vest lacks",
                    "vest's nodes name a key in a key port (key: /vars/x), or fill {/vars/x} "
                    "in a text",
                )
                continue
            args[port] = _value(text, param.type)
        if node_type.children == "many":
            return {node_type.name: {**args, "children": children}}
        if node_type.children == "one":
            if len(children) != 1:
                self.problems.add(element.mark, f"<{element.tag}> takes one child")
                return None
            return {node_type.name: {**args, "child": children[0]}}
        if children:
            self.problems.add(element.mark, f"<{element.tag}> takes no children (it is a leaf)")
            return None
        return {node_type.name: args}

    def node_type(self, tag: str) -> NodeType | None:
        for node_type in self.registry:
            if own_id(node_type) == tag:
                return node_type
        return None


def _as_options(body: Any) -> dict[str, Any]:
    if isinstance(body, list):
        return {"children": body}
    return dict(body)


def _whole(text: str) -> int | None:
    return int(text) if re.fullmatch(r"\s*\d{1,9}\s*", text) else None


def _value(text: str, param_type: Any) -> Any:
    """A port's text as the value our YAML would hold."""
    if text.startswith("json:"):
        try:
            return json.loads(text[5:])
        except ValueError:
            return text
    if isinstance(param_type, Boolean) and text.strip().lower() in ("true", "false"):
        return text.strip().lower() == "true"
    if isinstance(param_type, Integer) and _whole(text) is not None:
        return int(text)
    if isinstance(param_type, Number):
        try:
            number = float(text)
        except ValueError:
            return text
        return number if math.isfinite(number) else text
    if isinstance(param_type, ListOf):
        return [item for item in text.split(";") if item]
    if type(param_type).__name__ in ("Scalar", "AnyValue"):  # as vest export writes them
        if text in ("true", "false"):
            return text == "true"
        if JSON_NUMBER.fullmatch(text):
            number = json.loads(text)
            return number if math.isfinite(number) else text
    return text


def tree_yaml(text: str, name: str, registry: NodeRegistry) -> tuple[str, list[str]]:
    """The BehaviorTree.CPP v4 XML ``text`` (``name`` is its file, for messages) as our
    tree YAML, and what the person should know of it; LoadError naming each element or
    port vest has no counterpart for."""
    document = parse_xml(text, name)
    if document.tag != "root":
        raise LoadError([Problem(document.mark, f"<{document.tag}>: not a BehaviorTree.CPP file")])
    version = document.attributes.get("BTCPP_format", "")
    if version != "4":
        hint = "BehaviorTree.CPP 3's XML: convert it with its own tool first" if version else None
        found = f"BTCPP_format={version!r}" if version else "no BTCPP_format"
        raise LoadError([Problem(document.mark, f"{found}: vest reads version 4", hint)])
    trees: dict[str, Element] = {}
    for tree in (t for t in document.children if t.tag == "BehaviorTree"):
        tree_id = tree.attributes.get("ID", "")
        if tree_id in trees:
            raise LoadError([Problem(tree.mark, f"a second BehaviorTree with ID {tree_id!r}")])
        trees[tree_id] = tree
    if not trees:
        raise LoadError([Problem(document.mark, "no <BehaviorTree> in it")])
    main_id = document.attributes.get("main_tree_to_execute") or next(iter(trees))
    if main_id not in trees:
        raise LoadError([Problem(document.mark, f"main_tree_to_execute={main_id!r}: no such tree")])
    importer = _Importer(registry, trees)
    importer.opening.append(main_id)
    root = importer.tree_root(trees[main_id])
    importer.problems.raise_if_any()
    assert root is not None
    settings = _settings(trees[main_id])
    head = [
        f"# imported by vest from {name} (BehaviorTree {main_id!r})",
        f"name: {_scalar(main_id)}",
        f"rate_hz: {_scalar(settings.get('rate_hz', DEFAULT_RATE_HZ))}",
    ]
    if "rate_hz" not in settings:
        head[-1] += "   # BehaviorTree.CPP trees have no rate of their own"
    for key, default in (("priority", 0), ("wait_for_turn_s", 0.0), ("when_interrupted", "let_go")):
        if settings.get(key, default) != default:
            head.append(f"{key}: {_scalar(settings[key])}")
    wake_on = settings.get("wake_on")
    if isinstance(wake_on, list) and wake_on and all(isinstance(k, str) for k in wake_on):
        head.append(f"wake_on: [{', '.join(_scalar(key) for key in wake_on)}]")
    if settings.get("description"):
        head.append(f"description: {_scalar(str(settings['description']))}")
    notes = []
    if "rate_hz" not in settings:
        notes.append(
            f"{name}: no vest settings ({SETTINGS_ATTRIBUTE}: a tool dropped them, or the tree "
            f"was not made by vest): rate {DEFAULT_RATE_HZ:g} Hz, priority 0; set them in the YAML"
        )
    return "\n".join([*head, "root:", *_block(root, 1)]) + "\n", notes


def _settings(tree: Element) -> dict[str, Any]:
    """What our export kept of the tree's settings (``_vest_settings``), else nothing."""
    try:
        loaded = json.loads(tree.attributes.get(SETTINGS_ATTRIBUTE, "{}"))
    except ValueError:
        return {}
    return {k: v for k, v in loaded.items() if k in SETTINGS} if isinstance(loaded, dict) else {}


def _scalar(value: Any) -> str:
    text = yaml.safe_dump(
        value, default_flow_style=True, width=10_000, allow_unicode=True, sort_keys=False
    )
    return text.removesuffix("\n...\n").strip()


def _block(node: dict[str, Any], depth: int) -> list[str]:
    """``{Type: body}`` as our YAML block at ``depth`` (two spaces each)."""
    indent = "  " * depth
    note = f"   # {node[COMMENT]}" if COMMENT in node else ""
    ((kind, body),) = ((k, v) for k, v in node.items() if k != COMMENT)
    if isinstance(body, list):
        lines = [f"{indent}{kind}:{note}"]
        for child in body:
            lines += _item(child, depth + 2)
        return lines
    options = {k: v for k, v in body.items() if k not in ("children", "child")}
    if "children" not in body and "child" not in body:
        return [f"{indent}{kind}: {_scalar(options) if options else '{}'}{note}"]
    lines = [f"{indent}{kind}:{note}"]
    lines += [f"{indent}  {key}: {_scalar(value)}" for key, value in options.items()]
    if "child" in body:
        return [*lines, f"{indent}  child:", *_block(body["child"], depth + 2)]
    lines.append(f"{indent}  children:")
    for child in body["children"]:
        lines += _item(child, depth + 3)
    return lines


def _item(child: dict[str, Any], depth: int) -> list[str]:
    """A list item: ``- Type: ...`` with what follows indented under it."""
    lines = _block(child, depth)
    first = lines[0]
    return [first[: 2 * depth - 2] + "- " + first[2 * depth :], *lines[1:]]
