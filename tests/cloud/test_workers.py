"""Several service workers on one PostgreSQL database: a command queued in one wakes the
robot's long-poll in another, through LISTEN/NOTIFY."""

from __future__ import annotations

import asyncio
import socket
import threading

import pytest
from sqlalchemy.engine import make_url

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


def test_a_url_that_names_a_standby_too_finds_the_server_that_answers(postgres: object) -> None:
    """The failover form of docs/cloud.md: two servers in one URL (here the first one is
    down); the store and its listener both use the one that answers."""
    url = make_url(postgres.new_database())  # type: ignore[attr-defined]
    down = socket.socket()
    down.bind(("127.0.0.1", 0))  # a port nobody listens on: a primary that died
    dead_port = down.getsockname()[1]
    both = url.set(host=None, port=None).update_query_pairs(
        [("host", f"127.0.0.1:{dead_port}"), ("host", f"{url.host}:{url.port}")]
    )
    store = CloudStore.open(
        Settings(db_url=both.render_as_string(hide_password=False)), EpochClock()
    )
    try:
        store.directory.add_operator("ana")  # written through the one that answers
        assert store.listener is not None and store.listener.wait_listening(10.0)
    finally:
        store.close()
        down.close()
