"""A tree file as the editor sees it (an outline of nodes), and back to YAML a person can
still read: the round trip keeps comments, key order and layout of what was not changed.

The outline is plain JSON: the tree's settings (``name``, ``rate_hz``, ``priority``,
``wake_on``, ``description``), its ``params`` (the values a profile may change) and its
``root``, each node ``{"id", "type", "name",
"args", "children"}``. ``id`` names where the node stood in the file when it was read
(``root``, ``root/0``, ``root/0/child``); a node the page added has none. Writing the
outline back walks the file as read (ruamel.yaml's round-trip document) and changes only
what differs: a node whose id and type are kept keeps its mapping, its comments and its
flow or block style, and a parameter whose value is unchanged keeps its quotes. An
outline that changes nothing gives back the file's own text, byte for byte.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from ruamel.yaml.comments import CommentedMap, CommentedSeq

from engine.editor.round_trip import OutlineError, dumped, newline_of, plain, read, refilled, update
from engine.files.yaml_source import MAX_DEPTH
from engine.loader.tree_settings import SETTINGS as TREE_SETTINGS
from engine.nodes.registry import NodeRegistry

SETTINGS = ("name", "description", *(setting.name for setting in TREE_SETTINGS))
"""The tree's own settings the editor shows in its form (the rest stay as written)."""
SUBTREE = "Subtree"
STRUCTURE = ("child", "children")
"""A node's keys that hold its children, not its parameters."""


class TreeText:
    """One tree file's text, read for editing."""

    def __init__(self, text: str, registry: NodeRegistry) -> None:
        self.text = text
        self.registry = registry
        self.document, self.style = read(text)
        self.newline = newline_of(text)
        if not isinstance(self.document, CommentedMap) or "root" not in self.document:
            raise OutlineError("not a tree file (a tree has 'root:')")

    # -- the file to the outline ---------------------------------------------------------
    def outline(self) -> dict[str, Any]:
        """The settings and the root, as the page edits them."""
        settings = {key: plain(self.document[key]) for key in SETTINGS if key in self.document}
        raw_params = self.document.get("params")
        params = plain(raw_params) if isinstance(raw_params, CommentedMap) else {}
        root = self._node(self.document["root"], "root")
        return {"settings": settings, "params": params, "root": root}

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
                    args[str(key)] = plain(value)
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
        document = read(self.text)[0]  # a fresh copy: this one stays as read
        originals = dict(_originals(document["root"], "root"))
        settings = outline.get("settings", {})
        if not isinstance(settings, dict):
            raise OutlineError("settings must be a mapping")
        others = tuple(str(key) for key in document if key not in SETTINGS)
        update(document, {k: v for k, v in settings.items() if k in SETTINGS}, others)
        _params(document, outline.get("params", {}))
        _settings_first(document)
        document["root"] = self._built(outline.get("root"), originals, "root")
        return dumped(document, self.style, self.newline)

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
        many = self._children_of(type_name)
        if (many == "none" and children) or (many == "one" and len(children) > 1):
            takes = "no node under it" if many == "none" else "one node under it"
            raise OutlineError(f"{where}: {type_name} takes {takes}, got {len(children)}")
        if where.count("/") >= MAX_DEPTH:
            raise OutlineError(f"{where}: nested more than {MAX_DEPTH} deep")
        built = [self._built(child, originals, f"{where}/{i}") for i, child in enumerate(children)]
        if many == "many" and len(args) == 0 and not isinstance(body, CommentedMap):
            mapping[type_name] = refilled(body, built)
        elif many == "many":
            body = body if isinstance(body, CommentedMap) else CommentedMap()
            update(body, args, STRUCTURE)
            body["children"] = refilled(body.get("children"), built)
            mapping[type_name] = body
        else:
            body = body if isinstance(body, CommentedMap) else _new_body(many, args)
            update(body, args, STRUCTURE)
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


def _params(document: CommentedMap, params: Any) -> None:
    """The tree's ``params`` as the page set them: a changed value changed in place (its
    comment kept), a new one added, one taken out removed (and ``params`` with it when
    none is left)."""
    if not isinstance(params, dict) or not all(isinstance(k, str) for k in params):
        raise OutlineError("params must be a mapping of names to values")
    held = document.get("params")
    if not isinstance(held, CommentedMap):
        if not params:
            return
        held = CommentedMap()
        document.insert(list(document.keys()).index("root"), "params", held)
    update(held, params, ())
    if not held:
        del document["params"]


def _settings_first(document: CommentedMap) -> None:
    """A setting the page added goes where a person writes it: in the settings' order,
    above ``params`` and ``root`` (ruamel.yaml adds a new key at the end)."""
    keys = list(document.keys())
    body = [key for key in ("params", "root") if key in keys]
    if not body:
        return
    first_body = keys.index(body[0])
    late = [key for key in keys[first_body:] if key in SETTINGS]
    for key in sorted(late, key=SETTINGS.index):
        value = document.pop(key)
        document.insert(list(document.keys()).index(body[0]), key, value)
