"""List the blackboard keys trees may use: name, type, unit, writer, meaning."""

from __future__ import annotations

import argparse
import json

from engine.nodes.registry import default_registry

NAME = "keys"
HELP = "list the blackboard keys"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--format", choices=("text", "json"), default="text")


def main(args: argparse.Namespace) -> int:
    specs = list(default_registry().catalogue())  # with the keys plugins add
    if args.format == "json":
        print(
            json.dumps(
                [
                    {
                        "key": s.name,
                        "type": s.type_name,
                        "unit": s.unit,
                        "kind": s.kind,
                        "writer": s.writer,
                        "alias": s.alias,
                        "description": s.description,
                    }
                    for s in specs
                ],
                indent=2,
            )
        )
        return 0
    for spec in specs:
        unit = f" [{spec.unit}]" if spec.unit else ""
        event = " (event)" if spec.kind == "event" else ""
        print(f"{spec.name:28} {spec.type_name}{unit}{event}: {spec.description}")
    return 0
