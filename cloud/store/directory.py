"""Who may do what: people's accounts (with a role) and robots, their tokens (with an
expiry), and grants. Every change to them is written to the audit log in the same
transaction."""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

from sqlalchemy import select
from sqlalchemy.orm import Session

from cloud.roles import DEFAULT_ROLE, Permission, Role, may, role_named
from cloud.store.audit import Actor, AuditLog
from cloud.store.database import Database
from cloud.store.tables import GrantRow, OperatorRow, RobotRow
from cloud.store.tokens import digest, new_token, same_digest
from engine.clock import Clock, EpochClock
from engine.errors import ConfigError

NAME_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.")
DAY_S = 86_400.0
PERSON_DAYS = 90.0
"""How long a person's token works unless its admin says otherwise: a token forgotten in
a browser or a script stops working by itself."""
ROBOT_DAYS: float | None = None
"""A robot's token never expires unless its admin says: it sits in a file on a robot that
no one logs in to, and an expiry would cut the robot off in the middle of a session with a
child. Rotate it (`vest cloud rotate robot NAME`) when it may have leaked."""
MOST_DAYS = 3650.0
SHELL = Actor("shell", Role.ADMIN.value, "local")
"""Who changes accounts when no one is named: `vest cloud` on the service's host."""


@dataclass(frozen=True)
class Principal:
    """An authenticated caller: a person's account (``kind`` "operator", with its
    ``role``) or a robot (``role`` None), by id and name; ``expires_at_s``: when its token
    stops working (seconds since the epoch; None: never)."""

    kind: str  # "operator" or "robot"
    id: int
    name: str
    role: str | None = None
    expires_at_s: float | None = None

    def expired(self, now_s: float) -> bool:
        return self.expires_at_s is not None and now_s >= self.expires_at_s


def check_name(name: str, what: str) -> str:
    """A name of 1..64 letters, digits, - _ . (it appears in URLs)."""
    if not 1 <= len(name) <= 64 or not set(name) <= NAME_CHARS:
        raise ConfigError(f"{what} name {name!r}: use 1 to 64 letters, digits, '-', '_' or '.'")
    return name


def check_days(days: float | None) -> float | None:
    """``days`` (a token's lifetime) if above 0 and at most ten years; None: never expires."""
    if days is not None and not 0 < days <= MOST_DAYS:
        raise ConfigError(f"--expires-days {days:g}: use more than 0 and at most {MOST_DAYS:g}")
    return days


class Directory:
    """Accounts, robots, tokens and grants in ``db``; expiry measured on ``clock`` (seconds
    since the epoch), changes written to ``audit``."""

    def __init__(self, db: Database, clock: Clock | None = None) -> None:
        self.db = db
        self.clock = clock or EpochClock()
        self.audit = AuditLog(db, self.clock)

    def _expiry(self, days: float | None) -> float | None:
        check_days(days)
        return None if days is None else self.clock.now() + days * DAY_S

    def add_operator(
        self,
        name: str,
        role: str = DEFAULT_ROLE,
        expires_days: float | None = PERSON_DAYS,
        by: Actor = SHELL,
    ) -> str:
        """A new person's account of ``role``; returns its token (shown once: only its
        digest is kept), working for ``expires_days`` (None: never)."""
        check_name(name, "operator")
        role = role_named(role)
        token = new_token()
        with self.db.transaction() as session:
            if session.scalar(select(OperatorRow).where(OperatorRow.name == name)):
                raise ConfigError(f"there is already an operator {name!r}")
            expires_at_s = self._expiry(expires_days)
            session.add(
                OperatorRow(
                    name=name, token_digest=digest(token), role=role, expires_at_s=expires_at_s
                )
            )
            self.audit.write(
                session, by, "add-account", detail=f"{name} as {role}{_until(expires_at_s)}"
            )
        return token

    def add_robot(
        self, name: str, operator: str, expires_days: float | None = ROBOT_DAYS, by: Actor = SHELL
    ) -> str:
        """A new robot granted to ``operator``; returns its token (shown once)."""
        check_name(name, "robot")
        token = new_token()
        with self.db.transaction() as session:
            owner = self._operator(session, operator)
            if session.scalar(select(RobotRow).where(RobotRow.name == name)):
                raise ConfigError(f"there is already a robot {name!r}")
            expires_at_s = self._expiry(expires_days)
            robot = RobotRow(name=name, token_digest=digest(token), expires_at_s=expires_at_s)
            session.add(robot)
            session.flush()
            session.add(GrantRow(operator_id=owner.id, robot_id=robot.id))
            self.audit.write(
                session,
                by,
                "add-robot",
                robot=name,
                detail=f"granted to {operator}{_until(expires_at_s)}",
            )
        return token

    def grant(self, operator: str, robot: str, by: Actor = SHELL) -> None:
        """Let ``operator`` see ``robot`` (and command it, if its role may); again: nothing
        changes."""
        with self.db.transaction() as session:
            who = self._operator(session, operator)
            what = self._robot(session, robot)
            if session.get(GrantRow, (who.id, what.id)) is None:
                session.add(GrantRow(operator_id=who.id, robot_id=what.id))
                self.audit.write(session, by, "grant", robot=robot, detail=f"to {operator}")

    def revoke(self, kind: str, name: str, by: Actor = SHELL) -> None:
        """The token of operator or robot ``name`` no longer works."""
        with self.db.transaction() as session:
            row = self._row(session, kind, name)
            row.revoked = True
            robot, detail = _whose(kind, name)
            self.audit.write(session, by, "revoke", robot=robot, detail=detail)

    def set_role(self, name: str, role: str, by: Actor = SHELL) -> None:
        """Account ``name`` gets ``role`` (taken up within the service's token cache time)."""
        role = role_named(role)
        with self.db.transaction() as session:
            row = self._operator(session, name)
            was, row.role = row.role, role
            self.audit.write(session, by, "set-role", detail=f"{name}: {was} -> {role}")

    def rotate(self, kind: str, name: str, expires_days: float | None, by: Actor = SHELL) -> str:
        """A fresh token for operator or robot ``name``, working for ``expires_days`` (None:
        never); the old one stops working (within the service's token cache time). A
        revoked account works again with the new token."""
        token = new_token()
        with self.db.transaction() as session:
            row = self._row(session, kind, name)
            row.token_digest = digest(token)
            row.revoked = False
            row.expires_at_s = self._expiry(expires_days)
            robot, detail = _whose(kind, name, _until(row.expires_at_s).strip(", "))
            self.audit.write(session, by, "rotate", robot=robot, detail=detail)
        return token

    def authenticate(self, token: str, session: Session | None = None) -> Principal | None:
        """The operator or robot whose token this is, or None (unknown, revoked or expired).
        Asked inside another transaction, pass its ``session``: the lookup then takes no
        second connection from the pool (a claim waiting on a second one could starve it)."""
        holder = self.holder(token, session)
        return None if holder is None or holder.expired(self.clock.now()) else holder

    def holder(self, token: str, session: Session | None = None) -> Principal | None:
        """Whose token this is, expired or not (None: unknown or revoked)."""
        if session is not None:
            return self._holder(session, digest(token))
        with self.db.transaction() as own:
            return self._holder(own, digest(token))

    @staticmethod
    def _holder(session: Session, wanted: str) -> Principal | None:
        operator = session.scalar(select(OperatorRow).where(OperatorRow.token_digest == wanted))
        if operator is not None and same_digest(operator.token_digest, wanted):
            if operator.revoked:
                return None
            return Principal(
                "operator", operator.id, operator.name, operator.role, operator.expires_at_s
            )
        robot = session.scalar(select(RobotRow).where(RobotRow.token_digest == wanted))
        if robot is not None and same_digest(robot.token_digest, wanted):
            return (
                None
                if robot.revoked
                else Principal("robot", robot.id, robot.name, None, robot.expires_at_s)
            )
        return None

    def robots_of(self, person: Principal) -> list[RobotRow]:
        """The robots a person sees, by name: every one for an admin, else those granted."""
        query = select(RobotRow).order_by(RobotRow.name)
        if not may(person.role, Permission.EVERY_ROBOT):
            query = query.join(GrantRow, GrantRow.robot_id == RobotRow.id).where(
                GrantRow.operator_id == person.id
            )
        with self.db.transaction() as session:
            return list(session.scalars(query))

    def granted_robot(self, person: Principal, name: str) -> RobotRow | None:
        """The robot called ``name`` if the person sees it, else None (the caller cannot tell
        a robot it may not see from one that does not exist; a name no robot can have, a
        NUL in it say, is none)."""
        if not 1 <= len(name) <= 64 or not set(name) <= NAME_CHARS:
            return None
        query = select(RobotRow).where(RobotRow.name == name)
        if not may(person.role, Permission.EVERY_ROBOT):
            query = query.join(GrantRow, GrantRow.robot_id == RobotRow.id).where(
                GrantRow.operator_id == person.id
            )
        with self.db.transaction() as session:
            return session.scalar(query)

    def _row(self, session: Session, kind: str, name: str) -> OperatorRow | RobotRow:
        return self._operator(session, name) if kind == "operator" else self._robot(session, name)

    @staticmethod
    def _operator(session: Session, name: str) -> OperatorRow:
        row = session.scalar(select(OperatorRow).where(OperatorRow.name == name))
        if row is None:
            raise ConfigError(f"no operator {name!r}")
        return row

    @staticmethod
    def _robot(session: Session, name: str) -> RobotRow:
        row = session.scalar(select(RobotRow).where(RobotRow.name == name))
        if row is None:
            raise ConfigError(f"no robot {name!r}")
        return row


def _until(expires_at_s: float | None) -> str:
    """``", expires 2027-02-24"`` (UTC), or ``", never expires"``."""
    if expires_at_s is None:
        return ", never expires"
    return f", expires {dt.datetime.fromtimestamp(expires_at_s, dt.UTC):%Y-%m-%d %H:%M}Z"


def _whose(kind: str, name: str, detail: str = "") -> tuple[str | None, str]:
    """The audit's robot and detail naming a robot or an account."""
    if kind == "robot":
        return name, detail
    return None, f"account {name}" + (f", {detail}" if detail else "")
