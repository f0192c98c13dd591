"""A tree drawn: as ascii text, or as Graphviz dot (``vest render``, recordings, the view).

Nodes are numbered in depth-first order, ``n0`` being the root: the dot source names
each node so, and :func:`preorder` walks a tree's definitions in that same order.

The drawing is for people who do not program: composites and decorators say what they do
in plain words ("in order", "first that works", "at the same time", "rest 5 s"), labels
are wrapped to a few words a line, an included subtree is framed with its file's name, a
legend says what the shapes mean, and a tree wider than it is deep is laid out left to
right so twenty nodes stay readable.
"""

from __future__ import annotations

import logging
import shutil
import subprocess
import textwrap
from collections.abc import Iterator
from typing import Any

from engine.blackboard.catalogue import KeyCatalogue, default_catalogue
from engine.loader.node_sentences import node_sentence
from engine.loader.tree_definition import NodeDefinition, TreeDefinition
from engine.values.templates import CompiledTemplate

_SHAPES = {"composite": "box", "decorator": "hexagon", "condition": "ellipse", "action": "box"}
_COLORS = {
    "composite": "#FFD28C",
    "decorator": "#E6E6E6",
    "condition": "#B4DCFF",
    "action": "#B9F0B9",
}
log = logging.getLogger(__name__)
DOT_TIMEOUT_S = 20.0
"""The longest a drawing may take Graphviz (seconds): a huge tree is drawn, a stuck one
is given up."""
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


PLAIN_WORDS = {  # what a composite or decorator does, in the words a drawing uses
    "Sequence": "in order",
    "Selector": "first that works",
    "Parallel": "at the same time",
    "Inverter": "not",
    "ForceSuccess": "either way",
    "OneShot": "only once",
    "Cooldown": "not again for a while",
    "Timeout": "at most so long",
    "TimesWithin": "N times within T seconds",
    "HeldFor": "held for T seconds",
}
WRAP = 26
"""Characters a drawn label's line holds."""
LEGEND = (
    ("condition", "a question (yes / no)"),
    ("action", "something the robot does"),
    ("composite", "how its children run"),
    ("decorator", "a rule for its child"),
)


def plain_label(node: NodeDefinition, catalogue: KeyCatalogue | None = None) -> str:
    """What a node does, in a few words a line (for drawings people read); a leaf is said
    as :mod:`engine.loader.node_sentences` says it (its keys in ``catalogue``'s words)."""
    args, kind = node.args, node.type.name
    if kind == "Cooldown":
        start = " (from the start)" if args.get("counting_from") == "start" else ""
        head = f"not again for {_shown(args['seconds'])} s after acting{start}"
    elif kind == "Timeout":
        head = f"at most {_shown(args['seconds'])} s"
    elif kind == "TimesWithin":
        head = f"{_shown(args['times'])} times within {_shown(args['within_s'])} s"
    elif kind == "HeldFor":
        head = f"held for {_shown(args['seconds'])} s"
    elif kind in PLAIN_WORDS:
        head = PLAIN_WORDS[kind]
        if kind == "OneShot" and args.get("after") == "completion":
            head = "only once, even failed"
    elif kind in ("Repeat", "Retry"):
        head = f"{'repeat' if kind == 'Repeat' else 'retry'} {args['times']} times"
    elif (sentence := node_sentence(kind, node.args, catalogue or default_catalogue())) is not None:
        head = "\n".join(textwrap.wrap(sentence, WRAP, break_on_hyphens=False))
    else:
        parts = [kind]
        for param in node.type.params:
            value = args.get(param.name)
            if value is None or value == param.default:
                continue
            parts.append(f"{param.name}: {_shown(value)}")
        head = "\n".join(
            "\n".join(textwrap.wrap(part, WRAP, break_on_hyphens=False)) for part in parts
        )
    if node.name != node.type.name:
        head = f"{node.name}\n{head}"
    return head


def _shown(value: Any) -> str:
    if isinstance(value, CompiledTemplate):
        return f'"{value.source}"'
    if isinstance(value, list):
        return ", ".join(str(item) for item in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


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
    """The tree as Graphviz dot, nodes named ``n0..`` depth-first (the live view colors
    them by these names)."""
    name = escape(definition.name)
    catalogue = default_catalogue()  # the keys' words for the leaves' sentences
    widest = max(_widths(definition.root).values())
    deepest = max(depth for _, depth in preorder(definition.root))
    direction = "LR" if widest > 6 and widest > deepest else "TB"
    priority = f", priority {definition.priority}" if definition.priority else ""
    lines = [
        f'digraph "{name}" {{',
        f"  graph [rankdir={direction}, ordering=out, fontname=Helvetica, nodesep=0.25,"
        " ranksep=0.35];",
        '  node [style=filled, fontname=Helvetica, fontsize=11, margin="0.12,0.06"];',
        "  edge [arrowsize=0.6];",
        f'  title [shape=plaintext, style="", fontsize=13, '
        f'label="{name} ({definition.rate_hz:g} times a second{priority})"];',
    ]
    counter = iter(range(1_000_000))
    clusters = iter(range(1_000_000))

    def walk(node: NodeDefinition, indent: str) -> str:
        ident = f"n{next(counter)}"
        if node.subtree is not None:
            lines.append(f"{indent}subgraph cluster_{next(clusters)} {{")
            lines.append(
                f'{indent}  label="{escape(node.subtree)}"; style="rounded,dashed"; '
                'color="#78909C"; fontname=Helvetica; fontsize=10;'
            )
            inner = indent + "  "
        else:
            inner = indent
        kind = node.type.kind
        drawn = escape(plain_label(node, catalogue)).replace(chr(92) * 2 + "n", chr(92) + "n")
        lines.append(
            f'{inner}{ident} [shape={_SHAPES[kind]}, fillcolor="{_COLORS[kind]}", label="{drawn}"];'
        )
        edges = [f"{inner}{ident} -> {walk(child, inner)};" for child in node.children]
        lines.extend(edges)
        if node.subtree is not None:
            lines.append(f"{indent}}}")
        return ident

    root = walk(definition.root, "  ")
    lines.append(f"  title -> {root} [style=invis];")
    lines.append('  subgraph cluster_legend { label="legend"; fontname=Helvetica; fontsize=10;')
    lines.append('    style="rounded"; color="#B0BEC5";')
    for index, (kind, meaning) in enumerate(LEGEND):
        lines.append(
            f'    legend{index} [shape={_SHAPES[kind]}, fillcolor="{_COLORS[kind]}", '
            f'fontsize=9, label="{meaning}"];'
        )
    lines.append("  }")
    lines.append("}")
    return "\n".join(lines) + "\n"


def without_title_and_legend(dot: str) -> str:
    """``dot`` (from :func:`dot_source`, or a recording's copy of it) without its title and
    legend: a page that shows the tree's name above the drawing and one legend for all
    its drawings draws each tree without them."""
    kept: list[str] = []
    in_legend = False
    for line in dot.splitlines():
        if line.startswith("  subgraph cluster_legend"):
            in_legend = True
        elif in_legend:
            in_legend = line != "  }"
        elif not line.startswith(("  title [", "  title -> ")):
            kept.append(line)
    return "\n".join(kept) + "\n"


def svg_of(dot: str) -> bytes | None:
    """``dot`` drawn by Graphviz as SVG; None when Graphviz is missing or fails (logged)."""
    program = shutil.which("dot")
    if program is None:
        return None
    try:
        done = subprocess.run(
            [program, "-Tsvg"], input=dot.encode(), capture_output=True, timeout=DOT_TIMEOUT_S
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        log.error("drawing a tree failed: %s", error)
        return None
    if done.returncode != 0:
        log.error("Graphviz could not draw a tree: %s", done.stderr.decode(errors="replace"))
        return None
    return done.stdout


def _widths(root: NodeDefinition) -> dict[int, int]:
    """How many nodes each depth holds."""
    widths: dict[int, int] = {}
    for _, depth in preorder(root):
        widths[depth] = widths.get(depth, 0) + 1
    return widths
