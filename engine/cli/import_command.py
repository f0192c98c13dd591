"""Turn a BehaviorTree.CPP v4 XML tree into our YAML, when it uses what vest has (docs/
interop.md): BehaviorTree.CPP's nodes that mean what ours mean, our own node types, and
SubTrees (written in place). What has no counterpart is named with its line and column;
the YAML is checked as vest validate checks it before it is written.

  vest import hug.xml -o trees/hug.yaml
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
from pathlib import Path

from engine.cli.output import new_file, tell
from engine.cli.run_inputs import load_tree
from engine.errors import ConfigError
from engine.files.problems import LoadError
from engine.files.yaml_source import read_text
from engine.interop.btcpp_import import tree_yaml
from engine.nodes.registry import default_registry


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("xml", type=Path, metavar="FILE.xml")
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        metavar="TREE.yaml",
        help="file to write, never over one that is there (default: standard output)",
    )


def main(args: argparse.Namespace) -> int:
    if args.output is not None and (args.output.exists() or args.output.is_symlink()):
        raise ConfigError(f"-o {args.output}: is there already; name a new file")
    text = read_text(args.xml, str(args.xml))
    yaml_text, notes = tree_yaml(text, str(args.xml), default_registry())
    for note in notes:
        tell(f"warning: {note}")
    near = args.output if args.output is not None else Path("tree.yaml")  # its dialogs
    with tempfile.TemporaryDirectory() as scratch:
        checked = Path(scratch) / "imported.yaml"
        checked.write_text(yaml_text, encoding="utf-8")
        try:
            load_tree(checked, None, near=near)  # the same checks as vest validate
        except LoadError as error:  # the YAML is not written
            shown = re.sub(r"\S*imported\.yaml", f"({args.xml} as YAML)", str(error))
            raise ConfigError(f"the tree imported does not pass vest validate:\n{shown}") from None
    if args.output is None:
        sys.stdout.write(yaml_text)
        return 0
    descriptor = new_file(args.output, f"-o {args.output}")  # made meanwhile: not over it
    with os.fdopen(descriptor, "w", encoding="utf-8") as out:
        out.write(yaml_text)
    print(f"{args.output}: from {args.xml}")
    return 0
