"""Look back at a recorded session (`vest run --record FILE`).

Without --at: what the recording holds (trees, how long, how many actions). With --at
SECONDS: every tree's node statuses and the blackboard at that moment of the session.
With --view: the same page as `vest run --view`, with a time slider, play, steps, and
jumps to the next action or the next change of a chosen node (until Ctrl-C).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from engine.buttons.button_file import BUTTONS_TREE
from engine.cli.output import tell
from engine.cli.site_access import open_recording
from engine.cli.view_options import add_view_arguments, start_view
from engine.clock import RealClock
from engine.errors import UsageError
from engine.recording.replay import Recording, moment
from engine.view.replay_source import ReplaySource


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
    add_view_arguments(parser)


def _serve(recording: Recording, args: argparse.Namespace) -> int:
    """The replay page until Ctrl-C."""
    view = start_view(ReplaySource(recording), args)
    clock = RealClock()
    forever = clock.event()
    try:
        while not clock.wait(forever, 3600.0):
            pass
    finally:
        view.stop()
    return 0


def main(args: argparse.Namespace) -> int:
    recording, site = open_recording(args.recording, "replay")
    if site is not None:
        site.close()
    try:
        duration = recording.duration_s
        if args.view:
            return _serve(recording, args)
        if args.at is None:
            trees = recording.trees_at(duration)
            print(f"{args.recording}: a session of {duration:.2f} s (format {recording.format})")
            for tree in trees:
                versions = [t for t in recording.trees if t.name == tree.name]
                changed = "button actions" if tree.name == BUTTONS_TREE else "reloaded"
                reloads = f", {changed} {len(versions) - 1}x" if len(versions) > 1 else ""
                nodes = f"{len(tree.nodes)} node{'' if len(tree.nodes) == 1 else 's'}"
                print(f"  {tree.name}: {nodes} at {tree.rate_hz:g} Hz{reloads}")
            print(f"  {len(recording.actions())} actions; vest replay {args.recording} --at S")
            if recording.meta.get("left_out"):
                print(f"  not kept (no consent): {recording.meta['left_out']}")
            return _whole(recording)
        if args.at > duration:
            raise UsageError(f"--at {args.at:g}: the session lasted {duration:.2f} s")
        print(moment(recording, args.at))
        return _whole(recording)
    finally:
        recording.close()


def _whole(recording: Recording) -> int:
    """0 for a whole recording; 1, said on stderr, for one cut short or missing changes."""
    cut = recording.cut_short
    if cut is None:
        return 0
    tell(f"vest replay: {cut}")
    return 1
