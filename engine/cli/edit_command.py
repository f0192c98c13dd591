"""`vest edit [FOLDER]`: the tree editor in a browser, until Ctrl-C.

The folder's trees, subtrees, profiles and dialogs are listed; a tree is drawn as `vest
render` draws it and changed without writing YAML: nodes from a palette (the node
declarations, a plugin's nodes too), forms that know each parameter's type, unit, range and
the robot's pads, joints and colours, the checks of `vest validate` as you type, undo and
redo. Saving writes YAML a person can still edit by hand (comments and layout kept), never
over a file changed on disk meanwhile, never a tree with problems over one without unless
asked; a robot running `vest run` on the folder picks the change up by hot reload.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.cli.edit_checks import ValidateChecks
from engine.cli.edit_tries import HearCheck, TryOnSimulatedVest
from engine.cli.output import tell
from engine.cli.run_inputs import DEFAULT_HARDWARE, found, load_config, robot_catalogue
from engine.cli.stop_signals import serve_until_stopped
from engine.cli.view_options import port_number
from engine.editor.palette import palette
from engine.editor.server import EditorServer
from engine.editor.workspace import Workspace
from engine.errors import UsageError
from engine.files.problems import LoadError, Problems
from engine.nodes.registry import default_registry

DEFAULT_PORT = 8766


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "folder",
        type=Path,
        nargs="?",
        default=Path("."),
        metavar="FOLDER",
        help="the folder to edit (default: here; its trees/ and dialogs/ when it has them)",
    )
    parser.add_argument(
        "--port",
        type=port_number,
        default=DEFAULT_PORT,
        metavar="P",
        help=f"default {DEFAULT_PORT}",
    )
    parser.add_argument(
        "--host",
        default="127.0.0.1",
        metavar="ADDRESS",
        help="default loopback; another address serves a tablet (the address carries the "
        "token, as on loopback)",
    )
    parser.add_argument(
        "--hardware",
        type=Path,
        default=None,
        metavar="CONFIG",
        help=f"the robot whose pads, joints and devices trees are checked against "
        f"(default {DEFAULT_HARDWARE})",
    )


def main(args: argparse.Namespace) -> int:
    folder: Path = args.folder
    if not folder.is_dir():
        raise UsageError(f"FOLDER {folder}: no such folder")
    problems = Problems()
    hardware = args.hardware or found(DEFAULT_HARDWARE)
    config = load_config(hardware, problems) if hardware.is_file() else None
    if problems:
        raise LoadError(problems.items)
    if config is None:
        tell(f"note: no robot config ({hardware}): pads, joints and devices are not checked")
    registry = default_registry()
    workspace = Workspace(folder, registry, ValidateChecks(folder.resolve(), registry, config))
    offered = palette(registry, config, robot_catalogue(config, registry))
    try_out = TryOnSimulatedVest(folder.resolve(), hardware if config else None, offered["pads"])
    server = EditorServer(
        workspace,
        offered,
        host=args.host,
        port=args.port,
        try_out=try_out,
        hear_check=HearCheck(),
        watch=try_out.watch,
    )
    server.start()
    tell(f"editor: {server.url}  (the folder {workspace.folder}; Ctrl-C ends it)")
    try:
        serve_until_stopped()
    finally:
        server.stop()
        try_out.stop_watching()
    return 0
