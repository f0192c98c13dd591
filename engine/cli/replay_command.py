"""Look back at a recorded session (`vest run --record FILE`).

Without --at: what the recording holds (trees, how long, how many actions). With --at
SECONDS: every tree's node statuses and the blackboard at that moment of the session.
With --view: the same page as `vest run --view`, with a time slider, play, steps, and
jumps to the next action or the next change of a chosen node (until Ctrl-C).
"""

from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path

from engine.buttons.button_file import BUTTONS_TREE
from engine.cli.output import new_file, tell
from engine.cli.site_access import open_recording
from engine.cli.stop_signals import serve_until_stopped
from engine.cli.view_options import add_view_arguments, start_view
from engine.errors import ConfigError, UsageError
from engine.privacy.site import Site
from engine.recording.replay import STATUS_MARKS, Recording
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
    parser.add_argument(
        "--to",
        choices=("mcap", "btlog"),
        default=None,
        help="write the session for another tool: mcap (Foxglove, Lichtblick) or btlog "
        "(BehaviorTree.CPP's FileLogger2, which Groot2 replays; one tree: --tree)",
    )
    parser.add_argument("-o", "--output", type=Path, default=None, metavar="FILE")
    parser.add_argument("--tree", default=None, metavar="NAME", help="the tree, for --to btlog")
    add_view_arguments(parser)


def _serve(recording: Recording, args: argparse.Namespace) -> int:
    """The replay page until Ctrl-C."""
    view = start_view(ReplaySource(recording), args)
    try:
        serve_until_stopped()
    finally:
        view.stop()
    return 0


def main(args: argparse.Namespace) -> int:
    recording, site = open_recording(args.recording, "replay")
    try:
        if args.to is not None:
            return _converted(recording, site, args)
    finally:
        if site is not None:
            site.close()
        if args.to is not None:
            recording.close()
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


def _converted(recording: Recording, site: Site | None, args: argparse.Namespace) -> int:
    """The session written for another tool: a copy in the clear, its owner's alone, listed
    with the site (purged and erased with its recording)."""
    from engine.interop.session_formats import write_session
    from engine.nodes.registry import default_registry

    suffix = ".mcap" if args.to == "mcap" else ".btlog"
    output: Path = args.output or args.recording.with_suffix(suffix)
    if output.suffix != suffix:
        raise UsageError(f"-o {output}: a {args.to} file ends in {suffix}")
    if args.at is not None or args.view:
        raise UsageError("--to writes a file: without --at and --view")
    if args.tree is not None and args.to != "btlog":
        raise UsageError("--tree picks the tree of a btlog; an MCAP holds them all")
    tree = args.tree
    names = list(dict.fromkeys(t.name for t in recording.trees))
    if args.to == "btlog":
        if tree is None and len(names) != 1:
            raise UsageError(f"--to btlog holds one tree: add --tree, one of {', '.join(names)}")
        tree = names[0] if tree is None else tree
        if tree not in names:
            raise UsageError(f"--tree {tree}: not in this session; one of {', '.join(names)}")
    tags = {"composite": "Control"}
    kinds = {t.name: tags.get(t.kind, t.kind.title()) for t in default_registry()}
    descriptor = new_file(output, f"-o {output}", private=True)
    try:
        with os.fdopen(descriptor, "wb") as out:
            said = write_session(recording, args.to, out, tree, kinds)
    except OSError as error:
        output.unlink(missing_ok=True)  # ours: made a moment ago
        raise ConfigError(f"-o {output}: cannot write it ({error.strerror or error})") from None
    except ConfigError:  # a damaged recording, named already
        output.unlink(missing_ok=True)
        raise
    except (ValueError, OverflowError) as error:  # NaN, a time no calendar has
        output.unlink(missing_ok=True)
        raise ConfigError(f"{args.recording}: a damaged recording ({error})") from None
    except BaseException:  # a damaged recording named, Ctrl-C: no half-written file
        output.unlink(missing_ok=True)
        raise
    if site is not None:
        person = site.person_of(args.recording, recording.meta.get("person", ""))
        site.output_written(output, person, args.to, [args.recording])
    tell(f"{output}: {said}")
    return _whole(recording)


def _whole(recording: Recording) -> int:
    """0 for a whole recording; 1, said on stderr, for one cut short or missing changes."""
    cut = recording.cut_short
    if cut is None:
        return 0
    tell(f"vest replay: {cut}")
    return 1


def moment(recording: Recording, at_s: float) -> str:
    """The trees' statuses and the blackboard at ``at_s``, as ``vest replay --at`` prints."""
    statuses = recording.statuses_at(at_s)
    lines = [f"at {at_s:.2f} s of {recording.duration_s:.2f} s ({recording.path.name})"]
    for tree in recording.trees_at(at_s):
        reloaded = f", version {tree.version}" if tree.version > 1 else ""
        lines.append(f"\n{tree.name} ({tree.rate_hz:g} Hz{reloaded})")
        for node in tree.nodes:
            state = statuses.get((tree.name, tree.version, node.index))
            mark = STATUS_MARKS.get(state.status, "?") if state else "  "
            detail = f"  -- {state.feedback}" if state and state.feedback else ""
            lines.append(f"  [{mark}] {'  ' * node.depth}{node.label}{detail}")
    lines.append("\nblackboard")
    for key, written in sorted(recording.blackboard_at(at_s).items()):
        lines.append(f"  {key} = {json.dumps(written.value)}  (since {written.since_s:.2f} s)")
    done = recording.actions(at_s)
    if done:
        last = done[-1]
        lines.append(f"\nlast action: {last.at_s:.2f} s {last.tree} {last.action} {last.args}")
    around = [(at, what) for at, _, what in recording.world() if at <= at_s]
    if around:
        at, what = around[-1]
        lines.append(f"last around the robot: {at:.2f} s {what}")
    lines.append("\n[ok] success  [no] failure  [..] running  [  ] not ticked")
    return "\n".join(lines)
