"""Telemetry is kept in memory and written in batches; reads always see the newest."""

from __future__ import annotations

import pytest

from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.telemetry import MAX_KEYS, Telemetry, TelemetryFullError
from engine.clock import VirtualClock


def robot_id(directory: Directory, name: str = "hbs2") -> int:
    token = directory.add_robot(name, operator="ana")
    principal = directory.authenticate(token)
    assert principal is not None
    return principal.id


def test_pushes_are_read_at_once_and_written_in_one_batch(
    db: Database, directory: Directory, clock: VirtualClock
) -> None:
    directory.add_operator("ana")
    hbs2 = robot_id(directory)
    telemetry = Telemetry(db, clock)
    telemetry.put(hbs2, {"/sensors/force/left_n": 3.0, "/devices/touch/ok": True})
    clock.advance(1.0)
    telemetry.put(hbs2, {"/sensors/force/left_n": 4.5})
    assert telemetry.latest(hbs2)["/sensors/force/left_n"] == {"value": 4.5, "at_s": 1001.0}
    assert Telemetry(db, clock).latest(hbs2) == {}  # another worker: nothing written yet

    assert telemetry.flush() == 2
    other_worker = Telemetry(db, clock)
    assert other_worker.latest(hbs2) == {
        "/devices/touch/ok": {"value": True, "at_s": 1000.0},
        "/sensors/force/left_n": {"value": 4.5, "at_s": 1001.0},
    }
    assert telemetry.flush() == 0  # nothing new


def test_keys_stored_before_a_restart_or_by_another_worker_stay_and_count(
    db: Database, directory: Directory, clock: VirtualClock
) -> None:
    directory.add_operator("ana")
    hbs2 = robot_id(directory)
    before_restart = Telemetry(db, clock)
    before_restart.put(hbs2, {"/a": 1, "/b": 2, "/c": 3})
    before_restart.flush()
    clock.advance(1.0)
    one, two = Telemetry(db, clock), Telemetry(db, clock)  # the service again, two workers
    one.put(hbs2, {"/d": 4, "/a": 10})
    two.put(hbs2, {"/e": 5})
    clock.advance(1.0)
    two.put(hbs2, {"/a": 11})  # newer than what the first worker holds
    two.flush()
    one.flush()  # an older reading of /a, written after
    stored = Telemetry(db, clock).latest(hbs2)
    assert {key: reading["value"] for key, reading in stored.items()} == {
        "/a": 11,
        "/b": 2,
        "/c": 3,
        "/d": 4,
        "/e": 5,
    }
    counted = Telemetry(db, clock)
    counted.put(hbs2, {f"/new{i}": i for i in range(MAX_KEYS - 5)})  # exactly full
    with pytest.raises(TelemetryFullError, match="holds 500 keys"):
        counted.put(hbs2, {"/one_more": 0})


def test_last_seen_moves_forward_only_whichever_worker_writes_last(
    db: Database, directory: Directory, clock: VirtualClock
) -> None:
    ana = directory.authenticate(directory.add_operator("ana"))
    assert ana is not None
    hbs2 = robot_id(directory)
    early, late = Telemetry(db, clock), Telemetry(db, clock)
    early.seen(hbs2)
    clock.advance(5.0)
    late.seen(hbs2)
    late.flush()
    early.flush()  # an older time, written after
    stored = directory.robots_of(ana)[0].last_seen_s
    assert stored == 1005.0
    assert Telemetry(db, clock).last_seen(hbs2, stored) == 1005.0


def test_a_robot_waiting_in_a_long_poll_is_online(
    db: Database, directory: Directory, clock: VirtualClock
) -> None:
    directory.add_operator("ana")
    hbs2 = robot_id(directory)
    telemetry = Telemetry(db, clock)
    assert not telemetry.is_polling(hbs2)
    with telemetry.polling(hbs2):
        assert telemetry.is_polling(hbs2)
        clock.advance(25.0)
    assert not telemetry.is_polling(hbs2)
    assert telemetry.last_seen(hbs2, None) == 1025.0  # seen when the poll ended
