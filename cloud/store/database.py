"""Opening the database: a SQLite file (WAL mode, one writer at a time) or PostgreSQL by
URL. The schema is created when missing (migrations come with the service)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from sqlalchemy import Engine, create_engine, event
from sqlalchemy.exc import ArgumentError, DBAPIError
from sqlalchemy.orm import Session, sessionmaker

from cloud.store.tables import Table
from engine.errors import ConfigError


class Database:
    """An engine and its sessions; ``transaction()`` is one short transaction."""

    def __init__(self, url: str) -> None:
        try:
            self.engine: Engine = create_engine(url, future=True)
        except (ArgumentError, ImportError) as error:
            raise ConfigError(f"--db {url}: not a database URL we can open ({error})") from None
        if self.engine.dialect.name == "sqlite":
            event.listen(self.engine, "connect", _sqlite_pragmas)
        try:
            Table.metadata.create_all(self.engine)
        except DBAPIError as error:
            self.engine.dispose()
            raise ConfigError(f"--db {url}: cannot open it ({error.orig})") from None
        self._sessions = sessionmaker(self.engine, expire_on_commit=False)

    @contextmanager
    def transaction(self) -> Iterator[Session]:
        """A session whose work is committed at the end, or rolled back on an error."""
        with self._sessions.begin() as session:
            yield session

    def close(self) -> None:
        self.engine.dispose()


def _sqlite_pragmas(connection: Any, _record: Any) -> None:
    cursor = connection.cursor()
    cursor.execute("PRAGMA journal_mode=WAL")  # readers do not wait for the writer
    cursor.execute("PRAGMA foreign_keys=ON")
    cursor.execute("PRAGMA busy_timeout=5000")
    cursor.close()
