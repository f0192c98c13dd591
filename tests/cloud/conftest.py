"""A fresh SQLite store per test, on a virtual clock."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.ledger import CommandLedger
from engine.clock import VirtualClock


@pytest.fixture
def clock() -> VirtualClock:
    return VirtualClock(start_s=1000.0)


@pytest.fixture
def db(tmp_path: Path) -> Iterator[Database]:
    database = Database(f"sqlite:///{tmp_path / 'cloud.db'}")
    yield database
    database.close()


@pytest.fixture
def directory(db: Database) -> Directory:
    return Directory(db)


@pytest.fixture
def ledger(db: Database, clock: VirtualClock) -> CommandLedger:
    return CommandLedger(db, clock, lease_s=30.0, default_timeout_s=300.0)
