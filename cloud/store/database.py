"""Opening the database: a SQLite file (WAL mode, one writer at a time) or PostgreSQL by
URL, brought up to the newest schema by the migrations in cloud/migrations/."""

from __future__ import annotations

import fcntl
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from sqlalchemy import Connection, Engine, create_engine, event, make_url, text
from sqlalchemy.exc import ArgumentError, DBAPIError
from sqlalchemy.orm import Session, sessionmaker

from engine.errors import ConfigError

MIGRATIONS = Path(__file__).resolve().parent.parent / "migrations"
MIGRATION_LOCK = 0x7665_7374  # "vest": one process migrates a PostgreSQL database at a time


def engine_url(url: str) -> str:
    """``url`` with PostgreSQL's driver named (psycopg 3): ``postgresql://`` as people
    write it means ``postgresql+psycopg://`` here."""
    for scheme in ("postgresql://", "postgres://"):
        if url.startswith(scheme):
            return "postgresql+psycopg://" + url.removeprefix(scheme)
    return url


def shown_url(url: str) -> str:
    """``url`` with any password masked, for messages and logs."""
    try:
        return make_url(url).render_as_string(hide_password=True)
    except ArgumentError:
        return url


class Database:
    """An engine and its sessions; ``transaction()`` is one short transaction."""

    def __init__(self, url: str) -> None:
        shown = shown_url(url)
        try:
            self.engine: Engine = create_engine(engine_url(url), **_pool_options(url))
        except (ArgumentError, ImportError, ValueError) as error:
            raise ConfigError(
                f"--db {shown}: not a database URL we can open ({error}); use "
                "sqlite:///FILE or postgresql://USER@HOST/DATABASE"
            ) from None
        if self.engine.dialect.name == "sqlite":
            event.listen(self.engine, "connect", _sqlite_pragmas)
        try:
            self.migrate()
        except DBAPIError as error:
            self.engine.dispose()
            raise ConfigError(f"--db {shown}: cannot open it ({error.orig})") from None
        self._sessions = sessionmaker(self.engine, expire_on_commit=False)

    @property
    def is_postgresql(self) -> bool:
        return self.engine.dialect.name == "postgresql"

    def migrate(self) -> None:
        """Bring the schema up to the newest migration (nothing to do when it is), one
        process at a time (PostgreSQL: an advisory lock; SQLite: a lock file beside the
        database). ConfigError for a schema a newer vest made (this one cannot read it)."""
        with self._migration_lock(), self.engine.begin() as connection:
            if self.is_postgresql:  # released when the transaction ends
                connection.execute(text(f"SELECT pg_advisory_xact_lock({MIGRATION_LOCK})"))
            config = alembic_config(connection)
            heads = MigrationContext.configure(connection).get_current_heads()
            known = {
                script.revision for script in ScriptDirectory.from_config(config).walk_revisions()
            }
            if len(heads) > 1:  # vest's migrations are one line: never two at once
                raise ConfigError(
                    f"--db {shown_url(str(self.engine.url))}: its schema is recorded as at "
                    f"{len(heads)} revisions at once ({', '.join(map(repr, heads))}), which "
                    "no vest makes: it was changed by another program; restore a backup"
                )
            current = heads[0] if heads else None
            if current is not None and current not in known:
                raise ConfigError(
                    f"--db {shown_url(str(self.engine.url))}: its schema (revision "
                    f"{current!r}) was made by a newer vest than this one; update vest "
                    "(pip install -U vest-engine) or use a copy made before"
                )
            command.upgrade(config, "head")

    @contextmanager
    def _migration_lock(self) -> Iterator[None]:
        """For SQLite, an exclusive lock on ``FILE.migrate-lock`` while migrating: two
        commands opening a new database at once would both create its tables."""
        database = self.engine.url.database
        if self.is_postgresql or not database or database == ":memory:":
            yield
            return
        try:
            lock = open(f"{database}.migrate-lock", "a")  # noqa: SIM115 (held while migrating)
        except OSError:  # no such folder: opening the database says so, in its words
            yield
            return
        with lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                yield
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    @contextmanager
    def transaction(self) -> Iterator[Session]:
        """A session whose work is committed at the end, or rolled back on an error."""
        with self._sessions.begin() as session:
            yield session

    def close(self) -> None:
        self.engine.dispose()


def alembic_config(connection: Connection) -> Config:
    """Alembic's configuration for running the migrations on ``connection``."""
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    config.attributes["connection"] = connection
    return config


def _pool_options(url: str) -> dict[str, Any]:
    if url.startswith("sqlite"):
        return {}
    # long-polls hold no connection while they wait, but many robots claim at once
    return {"pool_size": 10, "max_overflow": 20, "pool_pre_ping": True}


def _sqlite_pragmas(connection: Any, _record: Any) -> None:
    cursor = connection.cursor()
    cursor.execute("PRAGMA journal_mode=WAL")  # readers do not wait for the writer
    cursor.execute("PRAGMA foreign_keys=ON")
    cursor.execute("PRAGMA busy_timeout=5000")
    cursor.close()
