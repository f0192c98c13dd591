"""The options of `vest run` that open the session to other tools: Foxglove and Lichtblick
(``--foxglove``) and a ROS 2 graph (``--ros2``, ``--ros2-commands``)."""

from __future__ import annotations

import argparse
import os
import re
import stat
from pathlib import Path
from typing import TYPE_CHECKING

from engine.blackboard.catalogue import READINGS
from engine.cli.output import tell
from engine.cli.view_options import port_number
from engine.errors import UsageError
from engine.interop.ros2_plan import ROUTER, Ros2Plan, namespace_from, namespace_problem

if TYPE_CHECKING:
    from engine.interop.foxglove_live import FoxgloveLive
    from engine.interop.ros2_bridge import Ros2Bridge


_ENDPOINT = re.compile(
    r"(tcp|udp|tls|quic)/[A-Za-z0-9.\-]+:\d{1,5}|(tcp|udp|tls|quic)/\[[0-9A-Fa-f:.]+\]:\d{1,5}"
)
"""A router's endpoint: protocol/host:port (an IPv6 host in brackets)."""
CONFIG_AT_MOST_BYTES = 1_000_000
_ORIGIN = re.compile(r"(https?|file)://[A-Za-z0-9.\-]*(\[[0-9A-Fa-f:.]+\])?(:\d{1,5})?/?")


def web_origin(text: str) -> str:
    """An origin as a browser sends it: scheme://host[:port], nothing after."""
    if not _ORIGIN.fullmatch(text):
        raise argparse.ArgumentTypeError(
            f"an origin is scheme://host[:port] with no path, e.g. https://app.foxglove.dev; "
            f"got {text!r}"
        )
    return text.rstrip("/")


def add_interop_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--foxglove",
        type=port_number,
        nargs="?",
        const=8767,
        default=None,
        metavar="PORT",
        help="serve the live session to Foxglove and Lichtblick (their WebSocket protocol) on "
        "127.0.0.1:PORT (default 8767, beside the view's 8765 and the editor's 8766; 0: any "
        "free port); the address "
        "vest prints carries its token",
    )
    parser.add_argument(
        "--foxglove-origin",
        type=web_origin,
        action="append",
        default=[],
        metavar="ORIGIN",
        help="a web page's origin that may connect to --foxglove with its token, e.g. "
        "https://app.foxglove.dev for Foxglove's web app (the desktop apps need none); again "
        "for more",
    )
    parser.add_argument(
        "--ros2",
        nargs="?",
        const=ROUTER,
        default=None,
        metavar="ROUTER",
        help=f"join a ROS 2 graph that runs rmw_zenoh through its Zenoh router (default {ROUTER}"
        "; ZENOH_SESSION_CONFIG_URI and ROS_DOMAIN_ID as ROS 2 reads them): the sensors, "
        "actions and each tree's BehaviorTreeLog as ROS 2 topics (docs/interop.md); needs "
        "pip install 'vest-engine[ros2]'",
    )
    parser.add_argument(
        "--ros2-commands",
        action="store_true",
        help="also take commands (say, led, move, read) on /<namespace>/vest/command, carried "
        "out by the iot_command tree as an operator's are; anyone on the graph may then send them",
    )
    parser.add_argument(
        "--ros2-namespace",
        default=None,
        metavar="NAME",
        help="the robot's ROS 2 namespace: its node is /NAME/vest and its topics /NAME/vest/... "
        "(default: the robot config's name, e.g. sim; '' for none), so two robots on one "
        "graph do not share topics",
    )


def ros2_plan(args: argparse.Namespace, robot_name: str) -> Ros2Plan | None:
    """The graph the options name (UsageError for a bad ROS_DOMAIN_ID, a namespace ROS 2
    refuses, or --ros2-commands or --ros2-namespace alone); None without --ros2. The
    namespace is ``robot_name``'s unless --ros2-namespace says."""
    if args.ros2 is None:
        if args.ros2_commands:
            raise UsageError("--ros2-commands takes commands from a ROS 2 graph: add --ros2")
        if args.ros2_namespace is not None:
            raise UsageError("--ros2-namespace names the robot on a ROS 2 graph: add --ros2")
        return None
    if args.ros2_namespace is None:
        namespace = namespace_from(robot_name)
    else:
        namespace = args.ros2_namespace.strip("/")
        problem = namespace_problem(args.ros2_namespace)
        if problem is not None:
            raise UsageError(f"--ros2-namespace {problem}")
    if not _ENDPOINT.fullmatch(args.ros2) or not 0 < int(args.ros2.rpartition(":")[2]) < 65536:
        raise UsageError(
            f"--ros2 {args.ros2!r}: the router's Zenoh endpoint, like tcp/192.168.1.20:7447 "
            "(tcp, udp, tls or quic; a port 1..65535)"
        )
    domain_text = os.environ.get("ROS_DOMAIN_ID", "0").strip() or "0"
    if not (domain_text.isascii() and domain_text.isdigit() and int(domain_text) <= 232):
        raise UsageError(f"ROS_DOMAIN_ID={domain_text!r}: a number 0..232, as in ROS 2")
    config_file = os.environ.get("ZENOH_SESSION_CONFIG_URI") or None
    if config_file is not None:
        _check_config_file(Path(config_file))
    return Ros2Plan(args.ros2, int(domain_text), args.ros2_commands, config_file, namespace)


def _check_config_file(path: Path) -> None:
    """A Zenoh config file Zenoh may read: a file of at most CONFIG_AT_MOST_BYTES."""
    where = f"ZENOH_SESSION_CONFIG_URI={path}"
    try:
        found = path.stat()
    except OSError as error:
        raise UsageError(f"{where}: cannot read it ({error.strerror})") from None
    if not stat.S_ISREG(found.st_mode):
        raise UsageError(f"{where}: not a file (a Zenoh config file, JSON5)")
    if found.st_size > CONFIG_AT_MOST_BYTES:
        raise UsageError(f"{where}: {found.st_size} bytes; a Zenoh config is a few kB")


def tell_foxglove(live: FoxgloveLive) -> None:
    tell(f"foxglove: {live.url} (in Foxglove: Open connection, Foxglove WebSocket)")


def tell_ros2(bridge: Ros2Bridge) -> None:
    node = f"{bridge.plan.prefix}/vest"
    taking = f"; commands on {node}/command" if bridge.plan.commands else ""
    tell(
        f"ros2: node {node} on domain {bridge.plan.domain} through {bridge.where}{taking} "
        "(ros2 topic list, with RMW_IMPLEMENTATION=rmw_zenoh_cpp)"
    )
    sent = (
        "sensor readings too (consent covers sensors and cloud_telemetry)"
        if READINGS in bridge.commands.gate.allowed
        else "the robot's own account only, no reading and no heard word (no consent to "
        "sensors and cloud_telemetry)"
    )
    tell(f"ros2: sends {sent}")
