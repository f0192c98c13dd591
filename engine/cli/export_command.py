"""Write a tree in another tool's format: BehaviorTree.CPP v4 XML, which Groot2 opens and
draws and BehaviorTree.CPP builds (docs/interop.md says which of our nodes become which of
theirs). Its subtrees become SubTrees; the profile's values are filled in.

  vest export trees/hug.yaml --format btcpp -o hug.xml
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from engine.cli.output import write_file
from engine.cli.run_inputs import load_tree
from engine.interop.btcpp_export import btcpp_xml


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("tree", type=Path, metavar="TREE.yaml")
    parser.add_argument(
        "--format",
        choices=("btcpp",),
        required=True,
        help="btcpp: BehaviorTree.CPP v4 XML (Groot2)",
    )
    parser.add_argument(
        "-o", "--output", type=Path, default=None, help="file to write (default: standard output)"
    )
    parser.add_argument(
        "--profile", default=None, help="a profile file, or a name in trees/profiles/"
    )


def main(args: argparse.Namespace) -> int:
    definition, registry = load_tree(args.tree, args.profile)
    text = btcpp_xml(definition, registry)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    write_file(args.output, text.encode("utf-8"), f"-o {args.output}", "the tree")
    print(f"{args.output}: {definition.name} as BehaviorTree.CPP v4 XML")
    return 0
