"""Run the cloud service and manage who may use it.

  vest cloud serve [--db URL] [--host H] [--port P] [--workers N]
                   [--certfile FILE --keyfile FILE] [--forwarded-allow-ips IPS]
  vest cloud add-operator NAME [--role ROLE] [--expires-days N|never]
                                        prints the account's token alone (shown once);
                                        add-account is the same command
  vest cloud add-robot NAME --operator NAME [--expires-days N|never]
                                        prints the robot's token alone (shown once)
  vest cloud set-role NAME ROLE         admin, operator, therapist or viewer
  vest cloud grant OPERATOR ROBOT
  vest cloud revoke operator|robot NAME
  vest cloud rotate operator|robot NAME [--expires-days N|never]
                                        prints a fresh token alone; the old one stops working
  vest cloud audit [--since WHEN] [--json]
Every one takes --db URL: a SQLite file (default sqlite:///vest-cloud.db) or postgresql://...
A setting not given on the command line is read from the environment when it is there
(``VEST_CLOUD_DB_URL``, ``VEST_CLOUD_LEASE_S``, ...: docs/cloud.md lists them).
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import re
from typing import TYPE_CHECKING, Any

from engine.cli.who import acting_user
from engine.clock import EpochClock
from engine.errors import UsageError

if TYPE_CHECKING:
    from cloud.services import CloudStore
    from cloud.settings import Settings
    from cloud.store.audit import Actor

ROLES = "admin, operator, therapist or viewer"
RELATIVE = re.compile(r"^(\d+(?:\.\d+)?)([dhm])$")
UNIT_S = {"d": 86_400.0, "h": 3_600.0, "m": 60.0}


def expires_days(text: str) -> float | None:
    """``--expires-days``: a number of days above 0, or ``never`` (None)."""
    if text.strip().lower() == "never":
        return None
    try:
        days = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give a number of days or 'never'") from None
    if not 0 < days <= 3650:
        raise argparse.ArgumentTypeError(f"{text}: use more than 0 and at most 3650 days")
    return days


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from cloud import DEFAULT_DB

    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)

    def action(name: str, help: str, aliases: tuple[str, ...] = ()) -> argparse.ArgumentParser:
        sub = actions.add_parser(name, help=help, description=help, aliases=list(aliases))
        sub.add_argument(
            "--db", metavar="URL", help=f"default $VEST_CLOUD_DB_URL, else {DEFAULT_DB}"
        )
        return sub

    def expiry(sub: argparse.ArgumentParser, default: str) -> None:
        sub.add_argument(
            "--expires-days",
            type=expires_days,
            metavar="N",
            default=argparse.SUPPRESS,
            help=f"days the token works, or 'never' (default {default})",
        )

    serve = action("serve", "run the service (HTTP or HTTPS, /api/v1)")
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
    serve.add_argument("--certfile", metavar="FILE", help="serve HTTPS: the PEM certificate")
    serve.add_argument("--keyfile", metavar="FILE", help="serve HTTPS: its PEM private key")
    serve.add_argument(
        "--forwarded-allow-ips",
        metavar="IPS",
        help="comma-separated addresses (or networks, or *) of reverse proxies whose "
        "X-Forwarded-For/-Proto headers are believed (default $FORWARDED_ALLOW_IPS, else "
        "127.0.0.1,::1; '' believes none)",
    )
    person = action(
        "add-operator", "add a person's account; prints its token", aliases=("add-account",)
    )
    person.add_argument("name")
    person.add_argument("--role", default="operator", help=f"{ROLES} (default operator)")
    expiry(person, "90")
    robot = action("add-robot", "add a robot, granted to an operator; prints its token")
    robot.add_argument("name")
    robot.add_argument("--operator", required=True, help="the operator who commands it")
    expiry(robot, "never")
    role = action("set-role", "give an account another role")
    role.add_argument("name")
    role.add_argument("role", help=ROLES)
    grant = action("grant", "let an operator see (and, if its role may, command) a robot")
    grant.add_argument("operator")
    grant.add_argument("robot")
    revoke = action("revoke", "make an operator's or robot's token stop working")
    revoke.add_argument("kind", choices=("operator", "robot"))
    revoke.add_argument("name")
    rotate = action("rotate", "give an operator or robot a fresh token; prints it")
    rotate.add_argument("kind", choices=("operator", "robot"))
    rotate.add_argument("name")
    expiry(rotate, "90 for an operator, never for a robot")
    audit = action("audit", "print the audit log: commands sent and canceled, account changes")
    audit.add_argument(
        "--since",
        metavar="WHEN",
        help="from this time on: 2026-11-26, 2026-11-26T10:00 (UTC unless it says), or "
        "ago: 7d, 12h, 30m",
    )
    audit.add_argument("--json", action="store_true", help="one JSON object a line")


def main(args: argparse.Namespace) -> int:
    from cloud.services import CloudStore
    from cloud.settings import Settings

    given = {"db_url": args.db}
    if args.action == "serve":
        given |= {"lease_s": args.lease_s, "default_timeout_s": args.timeout_s}
    settings = Settings(**{name: value for name, value in given.items() if value is not None})
    if args.action == "serve":
        return _serve(settings, args)
    since_s = _since(args.since, EpochClock().now()) if args.action == "audit" else None
    store = CloudStore.open(settings, EpochClock())
    try:
        _manage(store, args, since_s)
    finally:
        store.close()
    return 0


def _manage(store: CloudStore, args: argparse.Namespace, since_s: float | None) -> None:
    """One of the actions on accounts, robots and the audit log."""
    from cloud.store.directory import PERSON_DAYS, ROBOT_DAYS

    directory, by = store.directory, _shell_user()
    days: dict[str, Any] = (
        {"expires_days": args.expires_days} if "expires_days" in vars(args) else {}
    )
    if args.action in ("add-operator", "add-account"):
        print(directory.add_operator(args.name, role=args.role, by=by, **days))
    elif args.action == "add-robot":
        print(directory.add_robot(args.name, operator=args.operator, by=by, **days))
    elif args.action == "set-role":
        directory.set_role(args.name, args.role, by=by)
    elif args.action == "grant":
        directory.grant(args.operator, args.robot, by=by)
    elif args.action == "revoke":
        directory.revoke(args.kind, args.name, by=by)
    elif args.action == "rotate":
        default = PERSON_DAYS if args.kind == "operator" else ROBOT_DAYS
        print(directory.rotate(args.kind, args.name, days.get("expires_days", default), by=by))
    elif args.action == "audit":
        for entry in directory.audit.since(since_s):
            print(json.dumps(entry.as_json()) if args.json else entry.line())


def _shell_user() -> Actor:
    """Who runs `vest cloud` here, as the audit log names them."""
    from cloud.store.audit import Actor

    return Actor(f"shell:{acting_user()}"[:64], "admin", "local")


def _since(text: str | None, now_s: float) -> float | None:
    """``--since`` as seconds since the epoch: an ISO date or time (UTC unless it says),
    or a time ago (``7d``, ``12h``, ``30m``)."""
    if text is None:
        return None
    ago = RELATIVE.match(text.strip())
    if ago:
        return now_s - float(ago[1]) * UNIT_S[ago[2]]
    try:
        when = dt.datetime.fromisoformat(text.strip())
    except ValueError:
        raise UsageError(
            f"--since {text!r}: use a date or time (2026-11-26, 2026-11-26T10:00) or a time "
            "ago (7d, 12h, 30m)"
        ) from None
    return (when if when.tzinfo else when.replace(tzinfo=dt.UTC)).timestamp()


def _serve(settings: Settings, args: argparse.Namespace) -> int:
    from cloud.server import serve, serve_workers
    from cloud.store.database import Database
    from engine.web.tls import tls_options

    port, workers = args.port, args.workers
    if not 1 <= port <= 65535:
        raise UsageError(f"--port {port}: use 1..65535")
    if not 1 <= workers <= 64:
        raise UsageError(f"--workers {workers}: use 1..64")
    if workers > 1 and not settings.db_url.startswith(("postgresql", "postgres:")):
        raise UsageError(
            f"--workers {workers} needs a PostgreSQL --db (SQLite has one writer, and only "
            "PostgreSQL tells every worker that a command arrived)"
        )
    options: dict[str, object] = dict(tls_options(args.certfile, args.keyfile))
    if args.forwarded_allow_ips is not None:
        options["forwarded_allow_ips"] = _proxies(args.forwarded_allow_ips)
    Database(settings.db_url).close()  # a bad URL is named now, the schema brought up to date
    if workers == 1:
        serve(settings, args.host, port, options=options)
    else:
        serve_workers(settings, args.host, port, workers, options)
    return 0


def _proxies(text: str) -> str:
    """``--forwarded-allow-ips``: each item an address, a network or ``*`` ('' is none)."""
    import ipaddress

    for item in filter(None, (part.strip() for part in text.split(","))):
        if item != "*":
            try:
                ipaddress.ip_network(item, strict=False)
            except ValueError:
                raise UsageError(
                    f"--forwarded-allow-ips: {item!r} is not an address, a network "
                    "(10.0.0.0/8) or *"
                ) from None
    return text
