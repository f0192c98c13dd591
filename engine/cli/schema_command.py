"""Print a JSON Schema of tree files, for editors' completion and checks while typing.

Save it (``vest schema > tree.schema.json``) and put
``# yaml-language-server: $schema=tree.schema.json`` at the top of a tree file in an
editor with a YAML language server. ``vest validate`` remains the full check.
"""

from __future__ import annotations

import argparse
import json

from engine.nodes.registry import default_registry
from engine.nodes.schema import tree_schema


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """No options."""


def main(args: argparse.Namespace) -> int:
    print(json.dumps(tree_schema(default_registry()), indent=2))
    return 0
