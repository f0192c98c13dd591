"""The ``vest`` command line.

Exit codes: 0 success; 1 a file has problems (each printed as file:line:column); 2 the
command line is wrong; 3 something needed is missing on this machine (Graphviz, a bus, a
port, a device file).
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from engine.cli import (
    devices_command,
    keys_command,
    nodes_command,
    render_command,
    run_command,
    schema_command,
    validate_command,
)
from engine.errors import DeviceError, VestError
from engine.files.problems import LoadError

EXIT_OK, EXIT_PROBLEMS, EXIT_USAGE, EXIT_MISSING = 0, 1, 2, 3

EPILOG = """exit codes: 0 ok; 1 a file has problems (listed as file:line:column);
2 wrong command line; 3 something needed is missing on this machine"""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vest",
        description="Behavior-tree social interaction engine for robots wearing a sensor vest.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in (
        run_command,
        validate_command,
        render_command,
        nodes_command,
        keys_command,
        devices_command,
        schema_command,
    ):
        sub = commands.add_parser(
            module.NAME,
            help=module.HELP,
            description=module.__doc__,
            epilog=EPILOG,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        module.add_arguments(sub)
        sub.set_defaults(handler=module.main)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    logging.basicConfig(
        level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr
    )
    try:
        return int(args.handler(args))
    except LoadError as error:
        print(error, file=sys.stderr)
        count = len(error.problems)
        print(f"{count} problem{'s' if count != 1 else ''}", file=sys.stderr)
        return EXIT_PROBLEMS
    except DeviceError as error:  # a bus, port or chip this machine does not have
        print(f"vest {args.command}: {error}", file=sys.stderr)
        return EXIT_MISSING
    except VestError as error:
        print(f"vest {args.command}: {error}", file=sys.stderr)
        return EXIT_PROBLEMS
    except BrokenPipeError:  # e.g. `vest run --json | head`
        return EXIT_OK
