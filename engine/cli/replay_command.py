"""Look back at a recorded session (`vest run --record FILE`).

Without --at: what the recording holds (trees, how long, how many actions). With --at
SECONDS: every tree's node statuses and the blackboard at that moment of the session.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from engine.errors import UsageError
from engine.recording.replay import Recording, moment

NAME = "replay"
HELP = "show a recorded session at a moment (trees' statuses, the blackboard)"


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be seconds from the start, got {text!r}") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more seconds, got {text}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recording", type=Path, metavar="FILE", help="made by vest run --record")
    parser.add_argument(
        "--at", type=_seconds, default=None, metavar="SECONDS", help="the moment to show"
    )


def main(args: argparse.Namespace) -> int:
    recording = Recording.open(args.recording)
    try:
        duration = recording.duration_s
        if args.at is None:
            trees = recording.trees_at(duration)
            print(f"{args.recording}: a session of {duration:.2f} s (format {recording.format})")
            for tree in trees:
                versions = [t for t in recording.trees if t.name == tree.name]
                reloads = f", reloaded {len(versions) - 1}x" if len(versions) > 1 else ""
                print(f"  {tree.name}: {len(tree.nodes)} nodes at {tree.rate_hz:g} Hz{reloads}")
            print(f"  {len(recording.actions())} actions; vest replay {args.recording} --at S")
            return 0
        if args.at > duration:
            raise UsageError(f"--at {args.at:g}: the session lasted {duration:.2f} s")
        print(moment(recording, args.at))
        return 0
    finally:
        recording.close()
