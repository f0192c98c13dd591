"""The ledger's promise under concurrency: every change to a command is one compare-and-set,
so of two changes sent together one wins and the other is told how the command ended.

Each race is run many rounds with real concurrent transactions: two threads released
together by a barrier, each with its own ledger on its own database engine (as two service
workers have), on SQLite and on a real PostgreSQL; and once through the HTTP API of a
running service. A round's outcome may go either way; what must never happen is both
being told they won, or a state going back (a finished command QUEUED again, a canceled
one delivered).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from pathlib import Path
from typing import Any

import pytest
import requests

from cloud.settings import Settings
from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.ledger import (
    CANCELED,
    IN_PROGRESS,
    QUEUED,
    SUCCEEDED,
    CommandLedger,
    ConflictError,
)
from engine.clock import VirtualClock

ROUNDS = 25


@pytest.fixture
def two_workers(db_url: str, clock: VirtualClock) -> Iterator[tuple[CommandLedger, CommandLedger]]:
    """Two ledgers on one database, each with its own engine (as two workers)."""
    first, second = Database(db_url), Database(db_url)
    yield (
        CommandLedger(first, clock, lease_s=30.0, default_timeout_s=300.0),
        CommandLedger(second, clock, lease_s=30.0, default_timeout_s=300.0),
    )
    first.close()
    second.close()


@pytest.fixture
def robot(db_url: str, two_workers: tuple[CommandLedger, CommandLedger]) -> int:
    directory = Directory(two_workers[0].db)
    directory.add_operator("ana")
    found = directory.authenticate(directory.add_robot("hbs2", operator="ana"))
    assert found is not None
    return found.id


def together(*calls: Callable[[], Any]) -> list[Any]:
    """Run the calls at once (released together); each one's result, or the error it raised."""
    barrier = threading.Barrier(len(calls))

    def run(call: Callable[[], Any]) -> Any:
        barrier.wait()
        try:
            return call()
        except ConflictError as error:
            return error

    with ThreadPoolExecutor(len(calls)) as pool:
        return list(pool.map(run, calls))


def test_of_a_cancel_and_a_report_sent_together_exactly_one_wins(two_workers, robot) -> None:
    a, b = two_workers
    for _ in range(ROUNDS):
        command, _ = a.submit(robot, "say", {"text": "hi"})
        assert a.claim_next(robot) is not None
        canceled, reported = together(
            partial(a.cancel, robot, command.id),
            partial(b.report, robot, command.id, SUCCEEDED, {"ok": True}),
        )
        errors = [r for r in (canceled, reported) if isinstance(r, ConflictError)]
        assert len(errors) == 1, (canceled, reported)  # never both told they won
        final = a.get(robot, command.id)
        assert final is not None
        if isinstance(reported, ConflictError):
            assert final.state == CANCELED and final.result is None
            assert f"already ended {CANCELED}" in str(reported)
        else:
            assert final.state == SUCCEEDED and final.result == {"ok": True}
            assert f"already ended {SUCCEEDED}" in str(canceled)


def test_of_two_different_reports_exactly_one_is_kept(two_workers, robot) -> None:
    a, b = two_workers
    for _ in range(ROUNDS):
        command, _ = a.submit(robot, "read", {"sensor": "temperature"})
        assert a.claim_next(robot) is not None
        first, second = together(
            partial(a.report, robot, command.id, SUCCEEDED, {"c": 21.0}),
            partial(b.report, robot, command.id, SUCCEEDED, {"c": 22.0}),
        )
        winners = [r for r in (first, second) if not isinstance(r, ConflictError)]
        assert len(winners) == 1
        final = a.get(robot, command.id)
        assert final is not None and final.result == winners[0].result


def test_a_finished_command_never_goes_back_to_queued(two_workers, robot, clock) -> None:
    a, b = two_workers
    for _ in range(ROUNDS):
        command, _ = a.submit(robot, "say", {"text": "hi"})
        assert a.claim_next(robot) is not None
        clock.advance(31.0)  # its lease ran out: expire would put it back to QUEUED
        together(partial(a.report, robot, command.id, SUCCEEDED, None), b.expire)
        final = a.get(robot, command.id)
        assert final is not None
        if final.state == QUEUED:  # expire came first: the report was told it lost
            assert a.claim_next(robot) is not None  # and the robot is given it again
            a.report(robot, command.id, SUCCEEDED, None)
        assert a.get(robot, command.id).state == SUCCEEDED  # type: ignore[union-attr]


def test_a_command_answered_canceled_is_never_delivered_after_it(two_workers, robot) -> None:
    a, b = two_workers
    for _ in range(ROUNDS):
        command, _ = a.submit(robot, "say", {"text": "hi"})
        claimed, canceled = together(
            partial(a.claim_next, robot), partial(b.cancel, robot, command.id)
        )
        assert canceled.state == CANCELED
        if claimed is not None:  # the claim came first: the cancel found it IN_PROGRESS
            assert claimed.state == IN_PROGRESS and claimed.version < canceled.version
        assert a.claim_next(robot) is None


@pytest.fixture
def service(
    tmp_path: Path, start_service: Callable[..., Any], db_url: str
) -> tuple[str, dict[str, str], dict[str, str], Any]:
    """A running service with one operator and one robot: (api, operator's headers,
    robot's headers, store)."""
    running = start_service(Settings(db_url=db_url, max_wait_s=1.0, recheck_s=0.2))
    store = running.store
    operator = {"Authorization": f"Bearer {store.directory.add_operator('ana')}"}
    robot = {"Authorization": f"Bearer {store.directory.add_robot('hbs2', operator='ana')}"}
    return running.api, operator, robot, store


def test_over_http_a_cancel_and_a_result_sent_together_one_is_a_409(service) -> None:
    api, operator, robot, _ = service
    http = requests.Session()
    for _ in range(10):
        sent = http.post(
            f"{api}/robots/hbs2/commands",
            json={"type": "say", "args": {"text": "hi"}},
            headers=operator,
            timeout=10,
        )
        command_id = sent.json()["id"]
        claimed = http.get(f"{api}/robot/commands/next", headers=robot, timeout=10)
        assert claimed.status_code == 200
        cancel, result = together(
            partial(
                requests.post,
                f"{api}/robots/hbs2/commands/{command_id}/cancel",
                headers=operator,
                timeout=10,
            ),
            partial(
                requests.post,
                f"{api}/robot/commands/{command_id}/result",
                json={"status": "SUCCEEDED", "result": None},
                headers=robot,
                timeout=10,
            ),
        )
        codes = sorted((cancel.status_code, result.status_code))
        assert codes == [200, 409], (cancel.text, result.text)
        loser = cancel if cancel.status_code == 409 else result
        won = "SUCCEEDED" if cancel.status_code == 409 else "CANCELED"
        assert f"already ended {won}" in loser.text
