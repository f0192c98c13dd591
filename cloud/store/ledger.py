"""The command ledger: every command an operator sends, persisted before it is
acknowledged, delivered at least once under a lease, finished exactly once.

States: QUEUED -> IN_PROGRESS (claimed by the robot, under a lease) -> SUCCEEDED or FAILED
(the robot's report); CANCELED by the operator before it finished; TIMED_OUT past its
``timeout_s``. A robot still carrying a command out extends its lease; a lease that runs
out (the robot died, or lost its link) puts the command back to QUEUED: it is delivered
again, and the robot, which remembers what it carried out, reports the result it had.
``version`` grows with every change, and every change is one compare-and-set on (state,
version) in the database: of a cancel and a report sent together, or two reports, or a
claim and a cancel, one wins and the other is told how the command ended (ConflictError,
HTTP 409), on SQLite and PostgreSQL alike.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, Protocol

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session
from sqlalchemy.orm.exc import StaleDataError

from cloud.store.database import Database
from cloud.store.tables import CommandRow
from engine.clock import Clock
from engine.errors import VestError


class CommandState(StrEnum):
    """Where a command is: QUEUED (waiting for its robot), IN_PROGRESS (claimed, under a
    lease), then one of its ends. Stored as its name."""

    QUEUED = "QUEUED"
    IN_PROGRESS = "IN_PROGRESS"
    SUCCEEDED = "SUCCEEDED"
    FAILED = "FAILED"
    TIMED_OUT = "TIMED_OUT"
    CANCELED = "CANCELED"


QUEUED, IN_PROGRESS = CommandState.QUEUED, CommandState.IN_PROGRESS
SUCCEEDED, FAILED = CommandState.SUCCEEDED, CommandState.FAILED
TIMED_OUT, CANCELED = CommandState.TIMED_OUT, CommandState.CANCELED
FINISHED = frozenset({SUCCEEDED, FAILED, TIMED_OUT, CANCELED})
REPORTS = (SUCCEEDED, FAILED)
DEFAULT_LEASE_S = 30.0
DEFAULT_TIMEOUT_S = 300.0
CHANGE_ATTEMPTS = 50
"""How often a change that lost a race is decided again on what the winner left."""
EXPIRE_EVERY_S = 0.5
"""Leases and timeouts are looked at no more often than this (every long-poll's re-check
would otherwise scan the ledger)."""


class ChangeListener(Protocol):
    """Told of every change to a robot's commands: ``within`` inside the transaction that
    makes it (a PostgreSQL NOTIFY goes out when it commits), ``after`` once committed."""

    def within(self, session: Session, robot_id: int) -> None: ...

    def after(self, robot_id: int) -> None: ...


class ConflictError(VestError, ValueError):
    """A report that contradicts how the command already finished (HTTP 409)."""


@dataclass(frozen=True)
class Command:
    """One command as the ledger holds it."""

    id: str
    robot_id: int
    type: str
    args: dict[str, Any]
    state: CommandState
    version: int
    result: Any
    idempotency_key: str | None
    created_s: float
    updated_s: float
    timeout_at_s: float
    deliveries: int

    @classmethod
    def of(cls, row: CommandRow, now_s: float | None = None) -> Command:
        """The command as ``row`` holds it; with ``now_s``, as it stands then (a read
        never writes: a timeout or a lease that ran out since the last upkeep shows as
        TIMED_OUT or QUEUED, as the upkeep will store it)."""
        state = CommandState(row.state)
        lease_until_s = row.lease_until_s
        if now_s is not None and state in (QUEUED, IN_PROGRESS):
            if row.timeout_at_s <= now_s:
                state = TIMED_OUT
            elif state == IN_PROGRESS and lease_until_s is not None and lease_until_s <= now_s:
                state = QUEUED
        return cls(
            row.id,
            row.robot_id,
            row.type,
            dict(row.args),
            state,
            row.version,
            row.result,
            row.idempotency_key,
            row.created_s,
            row.updated_s,
            row.timeout_at_s,
            row.deliveries,
        )


class CommandLedger:
    """Commands in ``db``, on ``clock``; ``lease_s``: how long a claimed command waits for
    its report before it is delivered again."""

    def __init__(
        self,
        db: Database,
        clock: Clock,
        *,
        lease_s: float = DEFAULT_LEASE_S,
        default_timeout_s: float = DEFAULT_TIMEOUT_S,
        listener: ChangeListener | None = None,
    ) -> None:
        self.db = db
        self.clock = clock
        self.lease_s = lease_s
        self.default_timeout_s = default_timeout_s
        self.listener = listener
        self._expired_at_s = float("-inf")

    @contextmanager
    def _changing(self) -> Iterator[tuple[Session, set[int]]]:
        """A transaction, and the set to put the id of each robot whose commands it changes
        in: they are announced within it and again after it commits."""
        changed: set[int] = set()
        with self.db.transaction() as session:
            yield session, changed
            if self.listener is not None:
                for robot_id in changed:
                    self.listener.within(session, robot_id)
        if self.listener is not None:
            for robot_id in changed:
                self.listener.after(robot_id)

    def submit(
        self,
        robot_id: int,
        type: str,
        args: dict[str, Any],
        *,
        idempotency_key: str | None = None,
        timeout_s: float | None = None,
    ) -> tuple[Command, bool]:
        """The command, QUEUED and committed, and True; or, for an ``idempotency_key``
        already used for this robot, the command it made, and False (a ConflictError when
        that command was a different one: a key names one command)."""
        if idempotency_key is not None:
            known = self._by_key(robot_id, idempotency_key)
            if known is not None:
                return _same_command(known, type, args), False
        now = self.clock.now()
        row = CommandRow(
            id=str(uuid.uuid4()),
            robot_id=robot_id,
            type=type,
            args=args,
            state=QUEUED,
            version=1,
            result=None,
            idempotency_key=idempotency_key,
            created_s=now,
            updated_s=now,
            timeout_at_s=now + (timeout_s or self.default_timeout_s),
            lease_until_s=None,
            deliveries=0,
        )
        try:
            with self._changing() as (session, changed):
                session.add(row)
                changed.add(robot_id)
        except IntegrityError:  # the same key, sent twice at once: the other one won
            known = self._by_key(robot_id, idempotency_key or "")
            if known is None:
                raise
            return _same_command(known, type, args), False
        return Command.of(row), True

    def get(self, robot_id: int, command_id: str) -> Command | None:
        """The command as it stands now, only if it is this robot's (reads write nothing)."""
        if not _is_command_id(command_id):
            return None
        now_s = self.clock.now()
        with self.db.transaction() as session:
            row = session.get(CommandRow, command_id)
            return Command.of(row, now_s) if row is not None and row.robot_id == robot_id else None

    def recent(self, robot_id: int, limit: int = 50) -> list[Command]:
        """This robot's commands as they stand now, newest first (reads write nothing)."""
        now_s = self.clock.now()
        with self.db.transaction() as session:
            rows = session.scalars(
                select(CommandRow)
                .where(CommandRow.robot_id == robot_id)
                .order_by(CommandRow.created_s.desc(), CommandRow.id)
                .limit(limit)
            )
            return [Command.of(row, now_s) for row in rows]

    def _transition(
        self, robot_id: int, command_id: str, change: Callable[[CommandRow], bool]
    ) -> Command | None:
        """Read the command, let ``change`` change it (True when it did; it may raise
        ConflictError), and write it back only if nobody changed it meanwhile: one
        compare-and-set on its version. A change that lost the race is decided again on
        what the winner left. None when the command is not this robot's."""
        if not _is_command_id(command_id):
            return None
        for _ in range(CHANGE_ATTEMPTS):
            try:
                with self._changing() as (session, changed):
                    row = session.get(CommandRow, command_id)
                    if row is None or row.robot_id != robot_id:
                        return None
                    if change(row):
                        changed.add(robot_id)
                        session.flush()  # the compare-and-set: StaleDataError if it lost
                    return Command.of(row)
            except StaleDataError:
                continue
        raise ConflictError(f"command {command_id} is changing too fast; ask again")

    def cancel(self, robot_id: int, command_id: str) -> Command | None:
        """CANCELED if it had not finished; ConflictError naming how it ended when it had
        (a report or a timeout came first)."""

        def cancel(row: CommandRow) -> bool:
            if row.state == CANCELED:
                return False  # the same cancel again: answered as before
            if row.state in FINISHED:
                raise ConflictError(f"command {command_id} already ended {row.state}")
            self._change(row, CANCELED)
            row.lease_until_s = None
            return True

        return self._transition(robot_id, command_id, cancel)

    def claim_next(
        self,
        robot_id: int,
        before_taking: Callable[[Session], None] = lambda session: None,
        *,
        only_type: str | None = None,
    ) -> Command | None:
        """The oldest QUEUED command of this robot (of ``only_type``, when given), now
        IN_PROGRESS under a lease (one another claim or a cancel took first is passed
        over). ``before_taking`` is called when there is one to take, before it is taken,
        with the claim's session (to read on it, never on a second connection): what it
        raises leaves it QUEUED (a robot revoked meanwhile takes nothing)."""
        self.expire_due()
        for _ in range(CHANGE_ATTEMPTS):
            try:
                with self._changing() as (session, changed):
                    queued = select(CommandRow).where(
                        CommandRow.robot_id == robot_id,
                        CommandRow.state == QUEUED,
                        CommandRow.timeout_at_s > self.clock.now(),
                    )
                    if only_type is not None:
                        queued = queued.where(CommandRow.type == only_type)
                    row = session.scalar(
                        queued.order_by(CommandRow.created_s, CommandRow.id)
                        .limit(1)
                        .with_for_update(skip_locked=True)
                    )
                    if row is None:
                        return None
                    before_taking(session)
                    self._change(row, IN_PROGRESS)
                    row.lease_until_s = self.clock.now() + self.lease_s
                    row.deliveries += 1
                    changed.add(robot_id)
                    session.flush()  # the compare-and-set
                    return Command.of(row)
            except StaleDataError:
                continue
        return None  # every one taken meanwhile: the long-poll asks again

    def extend_lease(self, robot_id: int, command_id: str) -> Command | None:
        """The robot is still carrying the command out: its lease runs ``lease_s`` from now
        (one that ran out meanwhile and is QUEUED again is taken back). A finished command is
        answered as it is (CANCELED: the operator no longer wants it). None when the command
        is not this robot's."""
        self.expire_due()

        def extend(row: CommandRow) -> bool:
            if row.state == QUEUED:
                self._change(row, IN_PROGRESS)
            if row.state != IN_PROGRESS:
                return False
            row.lease_until_s = self.clock.now() + self.lease_s
            return True

        return self._transition(robot_id, command_id, extend)

    def report(self, robot_id: int, command_id: str, status: str, result: Any) -> Command | None:
        """The robot's report: SUCCEEDED or FAILED with its result. The same report again
        changes nothing; a different one for a finished command (another report, a cancel,
        a timeout came first) is a ConflictError naming how it ended. None when the command
        is not this robot's."""
        if status not in REPORTS:
            raise ValueError(f"status must be SUCCEEDED or FAILED, got {status!r}")

        def finish(row: CommandRow) -> bool:
            if row.state in FINISHED:
                if row.state == status and row.result == result:
                    return False
                raise ConflictError(f"command {command_id} already ended {row.state}")
            if row.timeout_at_s <= self.clock.now():  # ended, though the upkeep has not said so
                raise ConflictError(f"command {command_id} already ended {TIMED_OUT}")
            self._change(row, status)
            row.result = result
            row.lease_until_s = None
            return True

        return self._transition(robot_id, command_id, finish)

    def expire_due(self) -> None:
        """:meth:`expire`, at most every :data:`EXPIRE_EVERY_S` (the service's upkeep and
        every change call it)."""
        if self.clock.now() - self._expired_at_s >= EXPIRE_EVERY_S:
            self.expire()

    def expire(self) -> None:
        """Leases that ran out go back to QUEUED; commands past their timeout, TIMED_OUT.
        Each row is a compare-and-set: one a report or a cancel changed meanwhile is left
        as that change left it (the whole pass is made again on what is there now)."""
        now = self._expired_at_s = self.clock.now()
        for _ in range(CHANGE_ATTEMPTS):
            try:
                with self._changing() as (session, changed):
                    late = session.scalars(
                        select(CommandRow).where(
                            CommandRow.state.in_((QUEUED, IN_PROGRESS)),
                            (CommandRow.timeout_at_s <= now)
                            | (
                                (CommandRow.state == IN_PROGRESS)
                                & (CommandRow.lease_until_s <= now)
                            ),
                        )
                    )
                    for row in late:
                        if row.timeout_at_s <= now:
                            self._change(row, TIMED_OUT)
                        else:
                            self._change(row, QUEUED)  # its robot's long-poll takes it again
                        row.lease_until_s = None
                        changed.add(row.robot_id)
                    session.flush()
                return
            except StaleDataError:
                continue

    def _by_key(self, robot_id: int, key: str) -> Command | None:
        with self.db.transaction() as session:
            row = session.scalar(
                select(CommandRow).where(
                    CommandRow.robot_id == robot_id, CommandRow.idempotency_key == key
                )
            )
            return Command.of(row) if row is not None else None

    def _change(self, row: CommandRow, state: str) -> None:
        """A new state (``version`` grows as the row is written: the compare-and-set)."""
        row.state = state
        row.updated_s = self.clock.now()


def _is_command_id(text: str) -> bool:
    """Whether ``text`` can be a command's id (a UUID, as the ledger makes them): anything
    else (a NUL PostgreSQL cannot even compare) names no command."""
    try:
        return str(uuid.UUID(text)) == text
    except (ValueError, TypeError):
        return False


def _same_command(known: Command, type: str, args: dict[str, Any]) -> Command:
    if (known.type, known.args) != (type, args):
        raise ConflictError(
            f"idempotency_key {known.idempotency_key!r} was used for another command "
            f"({known.type} {known.args}); use a new key for a new command"
        )
    return known
