"""A tree drawn: as ascii text, or as Graphviz dot (``vest render``, recordings, the view).

Nodes are numbered in depth-first order, ``n0`` being the root: the dot source names
each node so, and :func:`preorder` walks a tree's definitions in that same order.
"""

from __future__ import annotations

from collections.abc import Iterator

from engine.loader.tree_definition import NodeDefinition, TreeDefinition
from engine.values.templates import CompiledTemplate

_SHAPES = {"composite": "box", "decorator": "hexagon", "condition": "ellipse", "action": "box"}
_COLORS = {
    "composite": "#FFD28C",
    "decorator": "#E6E6E6",
    "condition": "#B4DCFF",
    "action": "#B9F0B9",
}
_SYMBOLS = {"Sequence": "->", "Selector": "?", "Parallel": "=>"}


def preorder(node: NodeDefinition, depth: int = 0) -> Iterator[tuple[NodeDefinition, int]]:
    """``node`` and everything under it, depth-first (the dot source's numbering), with
    each one's depth below ``node``."""
    yield node, depth
    for child in node.children:
        yield from preorder(child, depth + 1)


def label(node: NodeDefinition) -> str:
    """``Check key=/sensors/force/left_n above=3`` : the type and the arguments given."""
    parts = [node.name if node.name != node.type.name else node.type.name]
    if node.name != node.type.name:
        parts.append(f"[{node.type.name}]")
    for param in node.type.params:
        value = node.args.get(param.name)
        if value is None or value == param.default:
            continue
        shown = f'"{value.source}"' if isinstance(value, CompiledTemplate) else f"{value}"
        parts.append(f"{param.name}={shown}")
    return " ".join(parts)


def ascii_tree(definition: TreeDefinition) -> str:
    lines = [f"{definition.name} ({definition.rate_hz:g} Hz)"]

    def walk(node: NodeDefinition, prefix: str, last: bool) -> None:
        branch = "`-- " if last else "|-- "
        symbol = _SYMBOLS.get(node.type.name)
        lines.append(prefix + branch + (f"[{symbol}] " if symbol else "") + label(node))
        for index, child in enumerate(node.children):
            walk(child, prefix + ("    " if last else "|   "), index == len(node.children) - 1)

    walk(definition.root, "", True)
    return "\n".join(lines) + "\n"


def escape(text: str) -> str:
    """``text`` inside a dot string: it cannot end the string or the line it is on."""
    return text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\r", "")


def dot_source(definition: TreeDefinition) -> str:
    name = escape(definition.name)
    lines = [
        f'digraph "{name}" {{',
        "  graph [rankdir=TB, fontname=Helvetica];",
        "  node [style=filled, fontname=Helvetica, fontsize=11];",
        f'  title [shape=plaintext, style="", label="{name} ({definition.rate_hz:g} Hz)"];',
    ]
    counter = iter(range(1_000_000))

    def walk(node: NodeDefinition) -> str:
        ident = f"n{next(counter)}"
        kind = node.type.kind
        lines.append(
            f'  {ident} [shape={_SHAPES[kind]}, fillcolor="{_COLORS[kind]}", '
            f'label="{escape(label(node))}"];'
        )
        for child in node.children:
            lines.append(f"  {ident} -> {walk(child)};")
        return ident

    root = walk(definition.root)
    lines += [f"  title -> {root} [style=invis];", "}"]
    return "\n".join(lines) + "\n"
