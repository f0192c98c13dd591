"""Operators and robots get a token once; only its digest is kept; grants say who sees what."""

from __future__ import annotations

import pytest
from sqlalchemy import event, select
from sqlalchemy.orm import Session

from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.ledger import CommandLedger
from cloud.store.principal_cache import PrincipalCache
from cloud.store.tables import OperatorRow, RobotRow
from engine.clock import VirtualClock
from engine.errors import ConfigError


def test_a_token_is_shown_once_and_only_its_digest_is_kept(
    directory: Directory, db: Database
) -> None:
    token = directory.add_operator("ana")
    with db.transaction() as session:
        stored = session.scalars(select(OperatorRow)).one()
    assert token not in stored.token_digest and len(stored.token_digest) == 64
    assert directory.authenticate(token).name == "ana"  # type: ignore[union-attr]


def test_a_robot_is_granted_to_its_operator_and_others_do_not_see_it(directory: Directory) -> None:
    ana = directory.authenticate(directory.add_operator("ana"))
    ben = directory.authenticate(directory.add_operator("ben"))
    assert ana is not None and ben is not None
    robot_token = directory.add_robot("hbs2", operator="ana")
    principal = directory.authenticate(robot_token)
    assert principal is not None and (principal.kind, principal.name) == ("robot", "hbs2")
    assert [r.name for r in directory.robots_of(ana)] == ["hbs2"]
    assert directory.robots_of(ben) == []
    directory.grant("ben", "hbs2")
    directory.grant("ben", "hbs2")  # again: nothing changes
    assert [r.name for r in directory.robots_of(ben)] == ["hbs2"]


def test_a_revoked_or_unknown_token_is_nobody(directory: Directory) -> None:
    directory.add_operator("ana")
    token = directory.add_robot("hbs2", operator="ana")
    directory.revoke("robot", "hbs2")
    assert directory.authenticate(token) is None
    assert directory.authenticate("not a token") is None


@pytest.mark.parametrize("name", ["", "a b", "x" * 65, "ünïcode", "../etc"])
def test_names_that_would_not_sit_in_a_url_are_refused(directory: Directory, name: str) -> None:
    with pytest.raises(ConfigError, match="use 1 to 64 letters"):
        directory.add_operator(name)


def test_two_of_one_name_or_an_unknown_operator_are_refused_by_name(directory: Directory) -> None:
    directory.add_operator("ana")
    with pytest.raises(ConfigError, match="already an operator 'ana'"):
        directory.add_operator("ana")
    with pytest.raises(ConfigError, match="no operator 'bob'"):
        directory.add_robot("hbs2", operator="bob")
    with directory.db.transaction() as session:
        assert session.scalars(select(RobotRow)).all() == []


def test_a_token_revoked_elsewhere_stops_working_within_the_cache_time(
    directory: Directory, clock: VirtualClock
) -> None:
    directory.add_operator("ana")
    token = directory.add_robot("hbs2", operator="ana")
    principals = PrincipalCache(directory, clock, ttl_s=5.0)
    assert principals.authenticate(token) is not None
    directory.revoke("robot", "hbs2")  # as `vest cloud revoke` does, from another process
    clock.advance(4.9)
    assert principals.authenticate(token) is not None  # still trusted, for a moment
    clock.advance(0.2)
    assert principals.authenticate(token) is None
    assert principals.authenticate("a guess") is None


def test_a_claim_asks_after_its_robots_token_on_its_own_connection(
    directory: Directory, clock: VirtualClock
) -> None:
    """Many long-polls claiming at once, each waiting on a second connection to check its
    token, would hold the whole pool and starve each other: the check reads on the claim's."""
    directory.add_operator("ana")
    token = directory.add_robot("hbs2", operator="ana")
    principals = PrincipalCache(directory, clock, ttl_s=0.0)  # never trusted from memory
    ledger = CommandLedger(directory.db, clock)
    robot = principals.authenticate(token)
    assert robot is not None
    ledger.submit(robot.id, "say", {"text": "hello"})
    held = [0]
    most = [0]

    def taken(*_: object) -> None:
        held[0] += 1
        most[0] = max(most[0], held[0])

    def given_back(*_: object) -> None:
        held[0] -= 1

    event.listen(directory.db.engine, "checkout", taken)
    event.listen(directory.db.engine, "checkin", given_back)
    checked: list[bool] = []

    def still_valid(session: Session) -> None:
        checked.append(principals.authenticate(token, session) is not None)

    assert ledger.claim_next(robot.id, still_valid) is not None
    assert checked == [True] and most[0] == 1
