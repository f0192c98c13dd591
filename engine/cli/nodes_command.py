"""List every node type the YAML may use, with parameters, from the registry.

``--format md`` prints the reference page docs/nodes.md is made from.
"""

from __future__ import annotations

import argparse
import json

from engine.nodes.docs import nodes_json, nodes_markdown
from engine.nodes.registry import default_registry


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--format",
        choices=("text", "md", "json"),
        default="text",
        help="text (default), md (Markdown reference) or json",
    )


def main(args: argparse.Namespace) -> int:
    registry = default_registry()
    if args.format == "md":
        print(nodes_markdown(registry), end="")
    elif args.format == "json":
        print(json.dumps(nodes_json(registry), indent=2))
    else:
        for node_type in registry:
            params = ", ".join(p.name for p in node_type.params)
            print(f"{node_type.name:13} {node_type.kind:10} {node_type.summary}")
            if params:
                print(f"{'':24} params: {params}")
    return 0
