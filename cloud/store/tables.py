"""The database tables. Times are seconds since the epoch (floats, UTC); JSON columns hold command
arguments, results and telemetry values."""

from __future__ import annotations

from typing import Any

from sqlalchemy import JSON, Float, ForeignKey, Index, Integer, MetaData, String, UniqueConstraint
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column

NAMING = {
    "ix": "ix_%(table_name)s_%(column_0_N_name)s",
    "uq": "uq_%(table_name)s_%(column_0_N_name)s",
    "fk": "fk_%(table_name)s_%(column_0_name)s_%(referred_table_name)s",
    "pk": "pk_%(table_name)s",
}
"""Every constraint named, so a migration can change it on SQLite (batch mode) too."""


class Table(DeclarativeBase):
    metadata = MetaData(naming_convention=NAMING)


class OperatorRow(Table):
    """A person's account (the table keeps its first name): its ``role`` (cloud/roles.py)
    and when its token expires (``expires_at_s``, None: never)."""

    __tablename__ = "operators"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    token_digest: Mapped[str] = mapped_column(String(64), unique=True)
    revoked: Mapped[bool] = mapped_column(default=False)
    role: Mapped[str] = mapped_column(String(16), default="operator", server_default="operator")
    expires_at_s: Mapped[float | None] = mapped_column(Float, default=None)


class RobotRow(Table):
    __tablename__ = "robots"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    token_digest: Mapped[str] = mapped_column(String(64), unique=True)
    revoked: Mapped[bool] = mapped_column(default=False)
    last_seen_s: Mapped[float | None] = mapped_column(Float, default=None)
    expires_at_s: Mapped[float | None] = mapped_column(Float, default=None)


class GrantRow(Table):
    """Operator ``operator_id`` may see and command robot ``robot_id``."""

    __tablename__ = "grants"

    operator_id: Mapped[int] = mapped_column(ForeignKey("operators.id"), primary_key=True)
    robot_id: Mapped[int] = mapped_column(ForeignKey("robots.id"), primary_key=True)


class CommandRow(Table):
    """One command. ``version`` grows with every change, and every change is a
    compare-and-set on it (``UPDATE ... WHERE version = <the version read>``): a change
    that lost a race to another changes nothing and is told so (StaleDataError)."""

    __tablename__ = "commands"
    __table_args__ = (
        UniqueConstraint("robot_id", "idempotency_key"),
        Index("ix_commands_claim", "robot_id", "state", "created_s"),
    )

    id: Mapped[str] = mapped_column(String(36), primary_key=True)
    robot_id: Mapped[int] = mapped_column(ForeignKey("robots.id"))
    type: Mapped[str] = mapped_column(String(64))
    args: Mapped[dict[str, Any]] = mapped_column(JSON)
    state: Mapped[str] = mapped_column(String(16), index=True)
    version: Mapped[int] = mapped_column(Integer, default=1)
    result: Mapped[Any] = mapped_column(JSON, nullable=True, default=None)
    idempotency_key: Mapped[str | None] = mapped_column(String(128), default=None)
    created_s: Mapped[float] = mapped_column(Float)
    updated_s: Mapped[float] = mapped_column(Float)
    timeout_at_s: Mapped[float] = mapped_column(Float)
    lease_until_s: Mapped[float | None] = mapped_column(Float, default=None)
    deliveries: Mapped[int] = mapped_column(Integer, default=0)

    __mapper_args__ = {"version_id_col": version}


class TelemetryRow(Table):
    """The latest telemetry of one robot: ``readings`` is {key: {"value", "at_s"}}, and
    ``at_s`` when the newest of them came (one row a robot: a batch writes one row per
    robot that pushed, not one per value)."""

    __tablename__ = "robot_telemetry"

    robot_id: Mapped[int] = mapped_column(ForeignKey("robots.id"), primary_key=True)
    readings: Mapped[dict[str, Any]] = mapped_column(JSON)
    at_s: Mapped[float] = mapped_column(Float)


class AuditRow(Table):
    """One thing a person did: sent or canceled a command, or changed an account. Only
    ever added to (the database refuses UPDATE and DELETE on it: migration 0003).
    ``actor`` and ``role`` are who did it and their role then; ``client`` the address it
    came from (the real client's behind a trusted proxy; ``local`` for the command line)."""

    __tablename__ = "audit_log"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    at_s: Mapped[float] = mapped_column(Float, index=True)
    actor: Mapped[str] = mapped_column(String(64))
    role: Mapped[str] = mapped_column(String(16))
    action: Mapped[str] = mapped_column(String(32))
    robot: Mapped[str | None] = mapped_column(String(64), default=None)
    detail: Mapped[str] = mapped_column(String(500), default="")
    client: Mapped[str] = mapped_column(String(64), default="")


class SessionViewRow(Table):
    """The live session of one robot as it last pushed it (``view``: trees, what happened,
    its button board, in the live view's words) and when (``at_s``)."""

    __tablename__ = "robot_session_view"

    robot_id: Mapped[int] = mapped_column(ForeignKey("robots.id"), primary_key=True)
    view: Mapped[dict[str, Any]] = mapped_column(JSON)
    at_s: Mapped[float] = mapped_column(Float)
