"""The command-line options of the view, shared by `vest run --view` and `vest replay --view`."""

from __future__ import annotations

import argparse

from engine.buttons.wizard import Wizard
from engine.cli.output import tell
from engine.composition.session_root import ViewPlan
from engine.view.server import ViewServer, ViewSource

DEFAULT_PORT = 8765


def port_number(text: str) -> int:
    """A port option's value (0: any free one)."""
    if not (text.isascii() and text.isdigit() and len(text) <= 5) or int(text) > 65535:
        raise argparse.ArgumentTypeError(
            f"must be a port number 0..65535 (0: any free), got {text!r}"
        )
    return int(text)


def add_view_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--view", action="store_true", help="show the trees live in a browser (prints the address)"
    )
    parser.add_argument(
        "--view-port",
        type=port_number,
        default=DEFAULT_PORT,
        metavar="P",
        help=f"default {DEFAULT_PORT}",
    )
    parser.add_argument(
        "--view-host",
        default="127.0.0.1",
        metavar="ADDRESS",
        help="default loopback; another address serves a lab's tablet (the address carries "
        "the token, as on loopback)",
    )


def view_plan(args: argparse.Namespace) -> ViewPlan:
    """Where the options put the view (its server makes a new token)."""
    return ViewPlan(args.view_host, args.view_port, None)


def tell_view(server: ViewServer) -> None:
    """The page's address on stderr (and the buttons' when it has them)."""
    tell(f"view: {server.url}")
    if server.wizard is not None:
        tell(f"buttons: {server.page_url('/buttons')}")


def start_view(
    source: ViewSource, args: argparse.Namespace, *, wizard: Wizard | None = None
) -> ViewServer:
    """Serve ``source`` (and the buttons of ``wizard``) as the options say and tell the
    addresses on stderr; DeviceError when the port is taken."""
    plan = view_plan(args)
    server = ViewServer(source, host=plan.host, port=plan.port, token=plan.token, wizard=wizard)
    server.start()
    tell_view(server)
    return server
