"""Several service workers on one PostgreSQL database: a command queued in one wakes the
robot's long-poll in another, through LISTEN/NOTIFY."""

from __future__ import annotations

import asyncio
import threading

import pytest

from cloud.services import CloudStore
from cloud.settings import Settings
from engine.clock import EpochClock, VirtualClock


@pytest.fixture
def two_workers(postgres: object) -> tuple[CloudStore, CloudStore]:
    url = postgres.new_database()  # type: ignore[attr-defined]
    settings = Settings(db_url=url)
    first = CloudStore.open(settings, EpochClock())
    second = CloudStore.open(settings, VirtualClock())  # its waits end only when woken
    yield first, second  # type: ignore[misc]
    first.close()
    second.close()


def test_a_command_queued_in_one_worker_wakes_the_long_poll_in_another(
    two_workers: tuple[CloudStore, CloudStore],
) -> None:
    first, second = two_workers
    first.directory.add_operator("ana")
    robot = first.directory.authenticate(first.directory.add_robot("hbs2", operator="ana"))
    assert robot is not None
    assert second.listener is not None and second.listener.wait_listening(10.0)
    woken: list[bool] = []
    waiter = threading.Thread(
        target=lambda: woken.append(asyncio.run(second.doorbell.wait(robot.id, 30.0)))
    )
    waiter.start()
    assert isinstance(second.clock, VirtualClock) and second.clock.until_waiting(1)
    first.ledger.submit(robot.id, "say", {"text": "hi"})  # notifies every worker
    waiter.join(timeout=30.0)
    assert woken == [True]  # the virtual clock never moved: only the notification woke it
    assert second.ledger.claim_next(robot.id) is not None


def test_sqlite_has_no_notifications_to_listen_for(tmp_path: object) -> None:
    store = CloudStore.open(Settings(db_url=f"sqlite:///{tmp_path}/c.db"), EpochClock())
    try:
        assert store.listener is None
    finally:
        store.close()
