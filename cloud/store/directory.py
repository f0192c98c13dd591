"""Who may do what: operators and robots with their tokens, and grants."""

from __future__ import annotations

from dataclasses import dataclass

from sqlalchemy import select
from sqlalchemy.orm import Session

from cloud.store.database import Database
from cloud.store.tables import GrantRow, OperatorRow, RobotRow
from cloud.store.tokens import digest, new_token, same_digest
from engine.errors import ConfigError

NAME_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.")


@dataclass(frozen=True)
class Principal:
    """An authenticated caller: an operator or a robot, by id and name."""

    kind: str  # "operator" or "robot"
    id: int
    name: str


def check_name(name: str, what: str) -> str:
    """A name of 1..64 letters, digits, - _ . (it appears in URLs)."""
    if not 1 <= len(name) <= 64 or not set(name) <= NAME_CHARS:
        raise ConfigError(f"{what} name {name!r}: use 1 to 64 letters, digits, '-', '_' or '.'")
    return name


class Directory:
    """Operators, robots, tokens and grants in ``db``."""

    def __init__(self, db: Database) -> None:
        self.db = db

    def add_operator(self, name: str) -> str:
        """A new operator; returns its token (shown once: only its digest is kept)."""
        check_name(name, "operator")
        token = new_token()
        with self.db.transaction() as session:
            if session.scalar(select(OperatorRow).where(OperatorRow.name == name)):
                raise ConfigError(f"there is already an operator {name!r}")
            session.add(OperatorRow(name=name, token_digest=digest(token)))
        return token

    def add_robot(self, name: str, operator: str) -> str:
        """A new robot granted to ``operator``; returns its token (shown once)."""
        check_name(name, "robot")
        token = new_token()
        with self.db.transaction() as session:
            owner = self._operator(session, operator)
            if session.scalar(select(RobotRow).where(RobotRow.name == name)):
                raise ConfigError(f"there is already a robot {name!r}")
            robot = RobotRow(name=name, token_digest=digest(token))
            session.add(robot)
            session.flush()
            session.add(GrantRow(operator_id=owner.id, robot_id=robot.id))
        return token

    def grant(self, operator: str, robot: str) -> None:
        """Let ``operator`` see and command ``robot`` (again: nothing changes)."""
        with self.db.transaction() as session:
            who = self._operator(session, operator)
            what = self._robot(session, robot)
            if session.get(GrantRow, (who.id, what.id)) is None:
                session.add(GrantRow(operator_id=who.id, robot_id=what.id))

    def revoke(self, kind: str, name: str) -> None:
        """The token of operator or robot ``name`` no longer works."""
        with self.db.transaction() as session:
            row = (
                self._operator(session, name) if kind == "operator" else self._robot(session, name)
            )
            row.revoked = True

    def authenticate(self, token: str, session: Session | None = None) -> Principal | None:
        """The operator or robot whose token this is, or None (unknown or revoked). Asked
        inside another transaction, pass its ``session``: the lookup then takes no second
        connection from the pool (a claim waiting on a second one could starve it)."""
        if session is not None:
            return self._holder(session, digest(token))
        with self.db.transaction() as own:
            return self._holder(own, digest(token))

    @staticmethod
    def _holder(session: Session, wanted: str) -> Principal | None:
        operator = session.scalar(select(OperatorRow).where(OperatorRow.token_digest == wanted))
        if operator is not None and same_digest(operator.token_digest, wanted):
            return None if operator.revoked else Principal("operator", operator.id, operator.name)
        robot = session.scalar(select(RobotRow).where(RobotRow.token_digest == wanted))
        if robot is not None and same_digest(robot.token_digest, wanted):
            return None if robot.revoked else Principal("robot", robot.id, robot.name)
        return None

    def robots_of(self, operator_id: int) -> list[RobotRow]:
        """The robots granted to an operator, by name."""
        with self.db.transaction() as session:
            query = (
                select(RobotRow)
                .join(GrantRow, GrantRow.robot_id == RobotRow.id)
                .where(GrantRow.operator_id == operator_id)
                .order_by(RobotRow.name)
            )
            return list(session.scalars(query))

    def granted_robot(self, operator_id: int, name: str) -> RobotRow | None:
        """The robot called ``name`` if it is granted to the operator, else None (the
        caller cannot tell a robot it may not see from one that does not exist; a name no
        robot can have, a NUL in it say, is none)."""
        if not 1 <= len(name) <= 64 or not set(name) <= NAME_CHARS:
            return None
        with self.db.transaction() as session:
            return session.scalar(
                select(RobotRow)
                .join(GrantRow, GrantRow.robot_id == RobotRow.id)
                .where(GrantRow.operator_id == operator_id, RobotRow.name == name)
            )

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
