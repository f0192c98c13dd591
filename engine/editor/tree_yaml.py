"""A tree file as the editor sees it (an outline of nodes), and back to YAML a person can
still read: the round trip keeps comments, key order and layout of what was not changed.

The outline is plain JSON: the tree's settings (``name``, ``rate_hz``, ``priority``,
``wake_on``, ``description``) and its ``root``, each node ``{"id", "type", "name",
"args", "children"}``. ``id`` names where the node stood in the file when it was read
(``root``, ``root/0``, ``root/0/child``); a node the page added has none. Writing the
outline back walks the file as read (ruamel.yaml's round-trip document) and changes only
what differs: a node whose id and type are kept keeps its mapping, its comments and its
flow or block style, and a parameter whose value is unchanged keeps its quotes. An
outline that changes nothing gives back the file's own text, byte for byte.
"""

from __future__ import annotations

import io
import re
from collections.abc import Iterator
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import YAMLError
from ruamel.yaml.scalarstring import DoubleQuotedScalarString

from engine.nodes.registry import NodeRegistry

SETTINGS = ("name", "description", "rate_hz", "priority", "wake_on")
"""The tree's own settings the editor shows in its form (the rest stay as written)."""
SUBTREE = "Subtree"
STRUCTURE = ("child", "children")
"""A node's keys that hold its children, not its parameters."""
STYLES = ((2, 4, 2), (2, 2, 2), (2, 2, 0), (4, 4, 2))
"""Indentation styles (mapping, sequence, dash offset) a file is tried against; the first
that reads and writes its text unchanged is the file's (vest's own files use the first)."""


PLAIN_WORD = re.compile(r"[A-Za-z_/#][A-Za-z0-9_./#-]*")
"""Text written without quotes: a word, a blackboard key, a colour (#FF5A8C)."""


class OutlineError(ValueError):
    """An outline or a file the editor cannot take, in words."""


def _yaml(style: tuple[int, int, int] = STYLES[0]) -> YAML:
    yaml = YAML()  # round-trip: comments, order, flow style and quotes are kept
    yaml.preserve_quotes = True
    yaml.width = 4096  # a line the person wrote is never wrapped anew
    mapping, sequence, offset = style
    yaml.indent(mapping=mapping, sequence=sequence, offset=offset)
    return yaml


def _dumped(document: Any, style: tuple[int, int, int]) -> str:
    out = io.StringIO()
    _yaml(style).dump(document, out)
    return out.getvalue()


class TreeText:
    """One tree file's text, read for editing."""

    def __init__(self, text: str, registry: NodeRegistry) -> None:
        self.text = text
        self.registry = registry
        try:
            self.document = _yaml().load(text)
        except YAMLError as error:
            raise OutlineError(f"not YAML the editor can read: {error}") from None
        if not isinstance(self.document, CommentedMap) or "root" not in self.document:
            raise OutlineError("not a tree file (a tree has 'root:')")
        self.style = next(
            (style for style in STYLES if _dumped(_yaml(style).load(text), style) == text),
            STYLES[0],
        )

    # -- the file to the outline ---------------------------------------------------------
    def outline(self) -> dict[str, Any]:
        """The settings and the root, as the page edits them."""
        settings = {key: _plain(self.document[key]) for key in SETTINGS if key in self.document}
        return {"settings": settings, "root": self._node(self.document["root"], "root")}

    def _node(self, raw: Any, ident: str) -> dict[str, Any]:
        if not isinstance(raw, CommentedMap) or len(raw) != 1:
            raise OutlineError(f"{ident}: a node is a mapping with one key, its type")
        type_name, body = next(iter(raw.items()))
        args: dict[str, Any] = {}
        name: str | None = None
        children: list[dict[str, Any]] = []
        if isinstance(body, CommentedSeq):
            children = [self._node(item, f"{ident}/{i}") for i, item in enumerate(body)]
        elif isinstance(body, CommentedMap):
            for key, value in body.items():
                if key == "name":
                    name = str(value)
                elif key == "child":
                    children = [self._node(value, f"{ident}/child")]
                elif key == "children" and isinstance(value, CommentedSeq):
                    children = [self._node(item, f"{ident}/{i}") for i, item in enumerate(value)]
                else:
                    args[str(key)] = _plain(value)
        return {"id": ident, "type": str(type_name), "name": name, "args": args,
                "children": children}  # fmt: skip

    def node_lines(self) -> list[tuple[int, str]]:
        """(line, id) of every node, in the file's order (lines count from 1): where a
        problem the validator found at a line belongs."""
        return sorted(
            (raw.lc.line + 1, ident) for ident, raw in _originals(self.document["root"], "root")
        )

    # -- the outline back to the file ----------------------------------------------------
    def written(self, outline: dict[str, Any]) -> str:
        """The file's text with ``outline``'s changes made; its own text when none."""
        if outline == self.outline():
            return self.text
        document = _yaml(self.style).load(self.text)  # a fresh copy: this one stays as read
        originals = dict(_originals(document["root"], "root"))
        settings = outline.get("settings", {})
        if not isinstance(settings, dict):
            raise OutlineError("settings must be a mapping")
        others = tuple(str(key) for key in document if key not in SETTINGS)
        _update(document, {k: v for k, v in settings.items() if k in SETTINGS}, others)
        document["root"] = self._built(outline.get("root"), originals, "root")
        return _dumped(document, self.style)

    def _built(self, node: Any, originals: dict[str, CommentedMap], where: str) -> CommentedMap:
        if not isinstance(node, dict) or not isinstance(node.get("type"), str):
            raise OutlineError(f"{where}: a node needs a type")
        type_name: str = node["type"]
        args = node.get("args") or {}
        children = node.get("children") or []
        if not isinstance(args, dict) or not isinstance(children, list):
            raise OutlineError(f"{where}: args is a mapping and children a list")
        if node.get("name"):
            args = {"name": str(node["name"]), **args}
        raw = originals.pop(str(node.get("id")), None)  # once: a second use is a new node
        same = raw is not None and next(iter(raw)) == type_name
        mapping = raw if same and raw is not None else CommentedMap()
        body = mapping.get(type_name) if same else None
        built = [self._built(child, originals, f"{where}/{i}") for i, child in enumerate(children)]
        many = self._children_of(type_name)
        if many == "many" and len(args) == 0 and not isinstance(body, CommentedMap):
            mapping[type_name] = _refilled(body, built)
        elif many == "many":
            body = body if isinstance(body, CommentedMap) else CommentedMap()
            _update(body, args, STRUCTURE)
            body["children"] = _refilled(body.get("children"), built)
            mapping[type_name] = body
        else:
            body = body if isinstance(body, CommentedMap) else _new_body(many, args)
            _update(body, args, STRUCTURE)
            if many == "one":
                if built:
                    body["child"] = built[0]
                else:
                    body.pop("child", None)
            mapping[type_name] = body
        return mapping

    def _children_of(self, type_name: str) -> str:
        if type_name == SUBTREE:
            return "none"
        node_type = self.registry.get(type_name)
        return node_type.children if node_type is not None else "none"


def _originals(raw: Any, ident: str) -> Iterator[tuple[str, CommentedMap]]:
    """Every node mapping of the file as read, by the id :meth:`TreeText.outline` gave it."""
    if not isinstance(raw, CommentedMap) or len(raw) != 1:
        return
    yield ident, raw
    body = next(iter(raw.values()))
    if isinstance(body, CommentedMap):
        if "child" in body:
            yield from _originals(body["child"], f"{ident}/child")
        body = body.get("children")
    if isinstance(body, CommentedSeq):
        for index, item in enumerate(body):
            yield from _originals(item, f"{ident}/{index}")


def _new_body(children: str, args: dict[str, Any]) -> CommentedMap:
    """A new node's mapping: a leaf's few parameters on one line, as vest's own files."""
    body = CommentedMap()
    if children == "none" and all(not isinstance(v, dict) for v in args.values()):
        body.fa.set_flow_style()
    return body


def _refilled(sequence: Any, items: list[CommentedMap]) -> CommentedSeq:
    """``sequence`` (its comments kept) holding ``items`` now."""
    kept = sequence if isinstance(sequence, CommentedSeq) else CommentedSeq()
    if list(kept) != items:
        kept[:] = items
    return kept


def _update(mapping: CommentedMap, values: dict[str, Any], kept: tuple[str, ...]) -> None:
    """``mapping`` holding ``values``: changed values set, others removed (but the keys in
    ``kept``, which the caller handles), unchanged ones left as written (their quotes and
    comments)."""
    for key in list(mapping.keys()):
        if key not in values and key not in kept:
            del mapping[key]
    for key, value in values.items():
        if key in mapping and _plain(mapping[key]) == value:
            continue
        mapping[key] = _yaml_value(value)


def _yaml_value(value: Any) -> Any:
    """A new value as YAML holds it; text other than one plain word (a pad, a key, a
    colour) in double quotes, as the therapist guide writes spoken text."""
    if isinstance(value, str) and not PLAIN_WORD.fullmatch(value):
        return DoubleQuotedScalarString(value)
    if isinstance(value, list):
        items = CommentedSeq(_yaml_value(item) for item in value)
        items.fa.set_flow_style()
        return items
    if isinstance(value, dict):
        return CommentedMap((str(k), _yaml_value(v)) for k, v in value.items())
    return value


def _plain(value: Any) -> Any:
    """A round-trip value as plain JSON (its quotes and styles dropped)."""
    if isinstance(value, dict):
        return {str(key): _plain(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_plain(item) for item in value]
    if isinstance(value, bool) or value is None:
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    return str(value)
