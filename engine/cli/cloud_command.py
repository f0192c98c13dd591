"""Run the cloud service and manage who may use it.

  vest cloud serve [--db URL] [--host H] [--port P] [--workers N]
  vest cloud add-operator NAME          prints the operator's token alone (shown once)
  vest cloud add-robot NAME --operator NAME   prints the robot's token alone (shown once)
  vest cloud grant OPERATOR ROBOT
  vest cloud revoke operator|robot NAME
Every one takes --db URL: a SQLite file (default sqlite:///vest-cloud.db) or postgresql://...
A setting not given on the command line is read from the environment when it is there
(``VEST_CLOUD_DB_URL``, ``VEST_CLOUD_LEASE_S``, ...: docs/cloud.md lists them).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from engine.clock import EpochClock
from engine.errors import UsageError

if TYPE_CHECKING:
    from cloud.settings import Settings


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from cloud import DEFAULT_DB

    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)

    def action(name: str, help: str) -> argparse.ArgumentParser:
        sub = actions.add_parser(name, help=help, description=help)
        sub.add_argument(
            "--db", metavar="URL", help=f"default $VEST_CLOUD_DB_URL, else {DEFAULT_DB}"
        )
        return sub

    serve = action("serve", "run the service (HTTP, /api/v1)")
    serve.add_argument("--host", default="127.0.0.1", help="default 127.0.0.1")
    serve.add_argument("--port", type=int, default=8080, help="default 8080")
    serve.add_argument(
        "--workers",
        type=int,
        default=1,
        help="service processes (default 1; more than one needs a PostgreSQL --db)",
    )
    serve.add_argument(
        "--lease-s",
        type=float,
        help="seconds a robot has to report a command it took before it is delivered again "
        "(default $VEST_CLOUD_LEASE_S, else 30)",
    )
    serve.add_argument(
        "--timeout-s",
        type=float,
        help="seconds a command may wait and run, unless it says otherwise "
        "(default $VEST_CLOUD_DEFAULT_TIMEOUT_S, else 300)",
    )
    action("add-operator", "add an operator; prints its token").add_argument("name")
    robot = action("add-robot", "add a robot, granted to an operator; prints its token")
    robot.add_argument("name")
    robot.add_argument("--operator", required=True, help="the operator who commands it")
    grant = action("grant", "let an operator see and command a robot")
    grant.add_argument("operator")
    grant.add_argument("robot")
    revoke = action("revoke", "make an operator's or robot's token stop working")
    revoke.add_argument("kind", choices=("operator", "robot"))
    revoke.add_argument("name")


def main(args: argparse.Namespace) -> int:
    from cloud.services import CloudStore
    from cloud.settings import Settings

    given = {"db_url": args.db}
    if args.action == "serve":
        given |= {"lease_s": args.lease_s, "default_timeout_s": args.timeout_s}
    settings = Settings(**{name: value for name, value in given.items() if value is not None})
    if args.action == "serve":
        return _serve(settings, args.host, args.port, args.workers)
    store = CloudStore.open(settings, EpochClock())
    try:
        if args.action == "add-operator":
            print(store.directory.add_operator(args.name))
        elif args.action == "add-robot":
            print(store.directory.add_robot(args.name, operator=args.operator))
        elif args.action == "grant":
            store.directory.grant(args.operator, args.robot)
        elif args.action == "revoke":
            store.directory.revoke(args.kind, args.name)
    finally:
        store.close()
    return 0


def _serve(settings: Settings, host: str, port: int, workers: int) -> int:
    from cloud.server import serve, serve_workers
    from cloud.store.database import Database

    if not 1 <= port <= 65535:
        raise UsageError(f"--port {port}: use 1..65535")
    if not 1 <= workers <= 64:
        raise UsageError(f"--workers {workers}: use 1..64")
    if workers > 1 and not settings.db_url.startswith(("postgresql", "postgres:")):
        raise UsageError(
            f"--workers {workers} needs a PostgreSQL --db (SQLite has one writer, and only "
            "PostgreSQL tells every worker that a command arrived)"
        )
    Database(settings.db_url).close()  # a bad URL is named now, the schema brought up to date
    if workers == 1:
        serve(settings, host, port)
    else:
        serve_workers(settings, host, port, workers)
    return 0
