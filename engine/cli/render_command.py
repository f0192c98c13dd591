"""Draw a YAML tree: ascii in the terminal, or dot / svg / png (svg and png need Graphviz).

Each node shows its type and the parameters it was given, so a drawing reads like the file.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from engine.cli.output import write_file
from engine.cli.run_inputs import load_tree
from engine.loader.tree_drawing import ascii_tree, dot_source


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


def main(args: argparse.Namespace) -> int:
    definition, _ = load_tree(args.tree, args.profile)
    if args.format in ("ascii", "dot"):
        text = ascii_tree(definition) if args.format == "ascii" else dot_source(definition)
        if args.output:
            write_file(args.output, text.encode("utf-8"), f"-o {args.output}", "the drawing")
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
        write_file(output, result.stdout, f"-o {output}", "the drawing")
    else:
        sys.stdout.buffer.write(result.stdout)
    return 0
