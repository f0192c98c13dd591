"""The command ledger: nothing lost, nothing carried out twice, every change versioned."""

from __future__ import annotations

import pytest
from sqlalchemy import select

from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.ledger import (
    CANCELED,
    FAILED,
    IN_PROGRESS,
    QUEUED,
    SUCCEEDED,
    TIMED_OUT,
    CommandLedger,
    ConflictError,
)
from cloud.store.tables import CommandRow
from engine.clock import VirtualClock


@pytest.fixture
def robots(directory: Directory) -> tuple[int, int]:
    directory.add_operator("ana")
    directory.add_robot("one", operator="ana")
    directory.add_robot("two", operator="ana")
    with directory.db.transaction() as session:
        from sqlalchemy import select

        from cloud.store.tables import RobotRow

        ids = {row.name: row.id for row in session.scalars(select(RobotRow))}
    return ids["one"], ids["two"]


def test_a_command_goes_queued_in_progress_succeeded(
    ledger: CommandLedger, robots: tuple[int, int]
) -> None:
    one, _ = robots
    command, created = ledger.submit(one, "say", {"text": "hello"})
    assert created and (command.state, command.version) == (QUEUED, 1)
    claimed = ledger.claim_next(one)
    assert claimed is not None and claimed.id == command.id
    assert (claimed.state, claimed.version, claimed.deliveries) == (IN_PROGRESS, 2, 1)
    done = ledger.report(one, command.id, SUCCEEDED, {"said": True})
    assert done is not None and (done.state, done.version, done.result) == (
        SUCCEEDED,
        3,
        {"said": True},
    )
    assert ledger.claim_next(one) is None


def test_the_same_idempotency_key_gives_the_same_command(
    ledger: CommandLedger, robots: tuple[int, int]
) -> None:
    one, _ = robots
    first, created = ledger.submit(one, "say", {"text": "hi"}, idempotency_key="k1")
    again, created_again = ledger.submit(one, "say", {"text": "hi"}, idempotency_key="k1")
    assert created and not created_again and again.id == first.id
    assert len(ledger.recent(one)) == 1


def test_a_robot_never_sees_another_robot_s_commands(
    ledger: CommandLedger, robots: tuple[int, int]
) -> None:
    one, two = robots
    command, _ = ledger.submit(one, "say", {"text": "for one"})
    assert ledger.claim_next(two) is None
    assert ledger.get(two, command.id) is None
    assert ledger.report(two, command.id, SUCCEEDED, None) is None
    assert ledger.cancel(two, command.id) is None


def test_commands_are_delivered_oldest_first(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    one, _ = robots
    ids = []
    for text in ("a", "b", "c"):
        ids.append(ledger.submit(one, "say", {"text": text})[0].id)
        clock.advance(0.001)
    assert [ledger.claim_next(one).id for _ in ids] == ids  # type: ignore[union-attr]
    assert [c.id for c in ledger.recent(one)] == ids[::-1]


def test_a_lease_that_runs_out_delivers_the_command_again(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    one, _ = robots
    command, _ = ledger.submit(one, "say", {"text": "hello"})
    ledger.claim_next(one)
    clock.advance(29.0)
    assert ledger.claim_next(one) is None  # still leased
    clock.advance(2.0)
    again = ledger.claim_next(one)
    assert again is not None and again.id == command.id and again.deliveries == 2
    # the robot carried it out the first time and reports what it had: accepted once
    ledger.report(one, command.id, SUCCEEDED, {"said": True})
    assert ledger.report(one, command.id, SUCCEEDED, {"said": True}).version == again.version + 1  # type: ignore[union-attr]


def test_a_robot_still_at_a_command_keeps_it_by_extending_its_lease(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    one, two = robots
    command, _ = ledger.submit(one, "move", {"joint": "neck", "angle_deg": 50})
    ledger.claim_next(one)
    for _ in range(4):  # a minute and a half of turning, the lease extended every 20 s
        clock.advance(20.0)
        kept = ledger.extend_lease(one, command.id)
        assert kept is not None and kept.state == IN_PROGRESS
    assert ledger.claim_next(one) is None  # never delivered again
    assert ledger.extend_lease(two, command.id) is None  # not another robot's to keep


def test_a_lease_extended_late_takes_the_command_back_and_a_canceled_one_says_so(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    one, _ = robots
    late, _ = ledger.submit(one, "say", {"text": "late"})
    ledger.claim_next(one)
    clock.advance(31.0)  # the link was down: the lease ran out
    ledger.expire()
    assert ledger.get(one, late.id).state == QUEUED  # type: ignore[union-attr]
    taken_back = ledger.extend_lease(one, late.id)
    assert taken_back is not None and taken_back.state == IN_PROGRESS
    assert taken_back.deliveries == 1  # it was never delivered twice
    ledger.cancel(one, late.id)
    assert ledger.extend_lease(one, late.id).state == CANCELED  # type: ignore[union-attr]


def test_a_different_report_for_a_finished_command_is_a_conflict(
    ledger: CommandLedger, robots: tuple[int, int]
) -> None:
    one, _ = robots
    command, _ = ledger.submit(one, "say", {"text": "hello"})
    ledger.claim_next(one)
    ledger.report(one, command.id, FAILED, {"error": "speaker unplugged"})
    with pytest.raises(ConflictError, match="already ended FAILED"):
        ledger.report(one, command.id, SUCCEEDED, None)


def test_a_command_past_its_timeout_is_timed_out_and_never_delivered(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    one, _ = robots
    command, _ = ledger.submit(one, "move", {"joint": "neck", "angle_deg": 10}, timeout_s=5.0)
    clock.advance(5.0)
    assert ledger.claim_next(one) is None
    assert ledger.get(one, command.id).state == TIMED_OUT  # type: ignore[union-attr]


def test_a_report_past_the_timeout_is_refused_before_the_upkeep_has_said_so(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    """A finished state never changes once readers saw it: a press taken at 1.9 s and
    reported at 2.1 s stays TIMED_OUT (the robot then never carries it out)."""
    one, _ = robots
    press, _ = ledger.submit(one, "press", {"button": 0, "by": "tess"}, timeout_s=2.0)
    clock.advance(1.9)
    assert ledger.claim_next(one) is not None
    clock.advance(0.2)
    assert ledger.get(one, press.id).state == TIMED_OUT  # type: ignore[union-attr]
    with pytest.raises(ConflictError, match="already ended TIMED_OUT"):
        ledger.report(one, press.id, SUCCEEDED, {"pressed": "Hello"})
    assert ledger.get(one, press.id).state == TIMED_OUT  # type: ignore[union-attr]


def test_a_canceled_command_is_not_delivered_and_its_late_report_conflicts(
    ledger: CommandLedger, robots: tuple[int, int]
) -> None:
    one, _ = robots
    queued, _ = ledger.submit(one, "say", {"text": "never"})
    assert ledger.cancel(one, queued.id).state == CANCELED  # type: ignore[union-attr]
    assert ledger.claim_next(one) is None
    with pytest.raises(ConflictError):
        ledger.report(one, queued.id, SUCCEEDED, None)


def test_nothing_is_lost_when_the_service_restarts(
    tmp_path, clock: VirtualClock, robots: tuple[int, int], db: Database
) -> None:
    one, _ = robots
    ledger = CommandLedger(db, clock)
    done, _ = ledger.submit(one, "say", {"text": "a"})
    ledger.claim_next(one)
    ledger.report(one, done.id, SUCCEEDED, None)
    running, _ = ledger.submit(one, "say", {"text": "b"})
    ledger.claim_next(one)
    waiting, _ = ledger.submit(one, "say", {"text": "c"})
    url = str(db.engine.url)
    db.close()
    reopened = CommandLedger(Database(url), clock)  # a new process on the same file
    states = {c.id: c.state for c in reopened.recent(one)}
    assert states == {done.id: SUCCEEDED, running.id: IN_PROGRESS, waiting.id: QUEUED}


def test_reading_a_command_writes_nothing_yet_says_how_it_stands_now(
    ledger: CommandLedger, robots: tuple[int, int], clock: VirtualClock
) -> None:
    """An operator's GET shows a command whose lease or timeout ran out as the upkeep will
    store it; only the upkeep (or a change) stores it."""
    one, _ = robots
    leased, _ = ledger.submit(one, "say", {"text": "leased"}, timeout_s=100.0)
    ledger.claim_next(one)
    forgotten, _ = ledger.submit(one, "say", {"text": "forgotten"}, timeout_s=10.0)
    clock.advance(31.0)  # past the lease of the first, the timeout of the second

    def stored() -> dict[str, tuple[str, int]]:
        with ledger.db.transaction() as session:
            return {row.id: (row.state, row.version) for row in session.scalars(select(CommandRow))}

    before = stored()
    assert ledger.get(one, leased.id).state == QUEUED  # type: ignore[union-attr]
    assert {c.id: c.state for c in ledger.recent(one)} == {
        leased.id: QUEUED,
        forgotten.id: TIMED_OUT,
    }
    assert stored() == before  # the reads wrote nothing
    assert before[leased.id][0] == IN_PROGRESS and before[forgotten.id][0] == QUEUED
    ledger.expire_due()  # what the service's upkeep does every second
    assert {key: state for key, (state, _) in stored().items()} == {
        leased.id: QUEUED,
        forgotten.id: TIMED_OUT,
    }
