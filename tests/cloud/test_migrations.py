"""The migrations build exactly the schema the code declares, on SQLite and PostgreSQL, and
carry what a database holds from one schema to the next (and back)."""

from __future__ import annotations

import sqlalchemy as sa
from alembic import command
from alembic.autogenerate import compare_metadata
from alembic.migration import MigrationContext
from alembic.script import ScriptDirectory

from cloud.store.database import Database, alembic_config, engine_url
from cloud.store.directory import Directory
from cloud.store.tables import Table
from cloud.store.telemetry import Telemetry
from engine.clock import VirtualClock


def test_a_new_database_gets_the_declared_schema_at_the_newest_revision(db: Database) -> None:
    with db.engine.connect() as connection:
        context = MigrationContext.configure(connection)
        assert compare_metadata(context, Table.metadata) == []
        newest = ScriptDirectory.from_config(alembic_config(connection)).get_current_head()
        assert context.get_current_revision() == newest


def test_opening_a_database_again_keeps_what_it_holds(db_url: str) -> None:
    first = Database(db_url)
    token = Directory(first).add_operator("ana")
    first.close()
    again = Database(db_url)  # migrations already applied: nothing to do
    try:
        assert Directory(again).authenticate(token) is not None
    finally:
        again.close()


def test_telemetry_stored_a_row_per_key_moves_to_a_row_per_robot_and_back(
    db_url: str, clock: VirtualClock
) -> None:
    engine = sa.create_engine(engine_url(db_url))
    with engine.begin() as connection:  # a database made by the first release
        command.upgrade(alembic_config(connection), "0001")
        connection.execute(
            sa.text(
                "INSERT INTO robots (id, name, token_digest, revoked)"
                " VALUES (1, 'hbs2', 'd', false)"
            )
        )
        connection.execute(
            sa.text(
                "INSERT INTO telemetry (robot_id, key, value, at_s) VALUES"
                " (1, '/sensors/force/left_n', '3.5', 100.0),"
                " (1, '/devices/touch/ok', 'true', 101.0)"
            )
        )
    db = Database(db_url)  # brought up to date on opening
    try:
        assert Telemetry(db, clock).latest(1) == {
            "/devices/touch/ok": {"value": True, "at_s": 101.0},
            "/sensors/force/left_n": {"value": 3.5, "at_s": 100.0},
        }
    finally:
        db.close()
    with engine.begin() as connection:
        command.downgrade(alembic_config(connection), "0001")
        rows = connection.execute(sa.text("SELECT key, at_s FROM telemetry ORDER BY key"))
        assert [tuple(row) for row in rows] == [
            ("/devices/touch/ok", 101.0),
            ("/sensors/force/left_n", 100.0),
        ]
    engine.dispose()
