"""Draw a YAML tree: ascii in the terminal, or dot / svg / png (svg and png need Graphviz).

Each node shows its type and the parameters it was given, so a drawing reads like the file.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from engine.dialogs.library import DialogLibrary, find_dialogs_folder
from engine.errors import ConfigError
from engine.loader.tree_definition import NodeDefinition, TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry
from engine.values.templates import CompiledTemplate

NAME = "render"
HELP = "draw a tree as ascii, dot, svg or png"

_SHAPES = {"composite": "box", "decorator": "hexagon", "condition": "ellipse", "action": "box"}
_COLORS = {
    "composite": "#FFD28C",
    "decorator": "#E6E6E6",
    "condition": "#B4DCFF",
    "action": "#B9F0B9",
}
_SYMBOLS = {"Sequence": "->", "Selector": "?", "Parallel": "=>"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("tree", type=Path, metavar="TREE.yaml")
    parser.add_argument("--format", choices=("ascii", "dot", "svg", "png"), default="ascii")
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        help="file to write (default: standard output; required for png)",
    )
    parser.add_argument(
        "--profile",
        default=None,
        help="a profile file, or a name in trees/profiles/ (child, adult)",
    )


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


def dot_source(definition: TreeDefinition) -> str:
    lines = [
        f'digraph "{definition.name}" {{',
        "  graph [rankdir=TB, fontname=Helvetica];",
        "  node [style=filled, fontname=Helvetica, fontsize=11];",
        f'  title [shape=plaintext, style="", label="{definition.name} '
        f'({definition.rate_hz:g} Hz)"];',
    ]
    counter = iter(range(1_000_000))

    def escape(text: str) -> str:
        return text.replace("\\", "\\\\").replace('"', '\\"')

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


def main(args: argparse.Namespace) -> int:
    from engine.cli.run_inputs import resolve_profile
    from engine.loader.substitution import load_profile

    registry = default_registry()
    catalogue = registry.catalogue()
    folder = find_dialogs_folder(args.tree)
    dialogs = DialogLibrary.from_folder(folder, catalogue) if folder else None
    profile_path = resolve_profile(args.profile, [args.tree])  # by name or path, as vest run
    profile = load_profile(profile_path) if profile_path else None
    loader = TreeLoader(registry, catalogue, dialogs=dialogs, profile=profile)
    definition = loader.load(args.tree)
    if args.format in ("ascii", "dot"):
        text = ascii_tree(definition) if args.format == "ascii" else dot_source(definition)
        if args.output:
            _write(args.output, text.encode("utf-8"))
        else:
            sys.stdout.write(text)
        return 0
    return _graphviz(dot_source(definition), args.format, args.output)


def _graphviz(source: str, fmt: str, output: Path | None) -> int:
    import subprocess

    dot = shutil.which("dot")
    if dot is None:
        print(
            "vest render: svg and png need Graphviz's `dot` (apt-get install graphviz); "
            "--format dot or ascii work without it",
            file=sys.stderr,
        )
        return 3
    if fmt == "png" and output is None:
        print("vest render: png needs -o FILE", file=sys.stderr)
        return 2
    result = subprocess.run(
        [dot, f"-T{fmt}"], input=source.encode(), capture_output=True, check=False
    )
    if result.returncode != 0:
        print(f"vest render: dot failed: {result.stderr.decode(errors='replace')}", file=sys.stderr)
        return 3
    if output:
        _write(output, result.stdout)
    else:
        sys.stdout.buffer.write(result.stdout)
    return 0


def _write(path: Path, data: bytes) -> None:
    try:
        path.write_bytes(data)
    except OSError as error:
        raise ConfigError(f"-o {path}: {error.strerror or error}") from None
