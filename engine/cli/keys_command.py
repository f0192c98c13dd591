"""List the blackboard keys trees may use (name, type, unit, writer, meaning), and draw
the vest with its pads' names."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from engine.cli.run_inputs import DEFAULT_HARDWARE, found
from engine.hardware.config_file import load_robot_config
from engine.hardware.vest_picture import vest_picture
from engine.nodes.registry import default_registry


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument(
        "--pads", action="store_true", help="only draw the vest with its pads' names"
    )
    parser.add_argument(
        "--hardware",
        type=Path,
        metavar="CONFIG",
        help=f"the robot whose pads are drawn (default {DEFAULT_HARDWARE})",
    )


def main(args: argparse.Namespace) -> int:
    default = found(DEFAULT_HARDWARE)
    hardware = args.hardware or (default if default.is_file() else None)
    picture = vest_picture(load_robot_config(hardware)) if hardware is not None else None
    if args.pads:
        if picture is None:
            print("vest keys --pads: no robot config (give --hardware CONFIG)")
            return 1
        print(picture, end="")
        return 0
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
    if picture is not None:
        print("\n" + picture, end="")
    return 0
