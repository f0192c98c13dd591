"""The migrations build exactly the schema the code declares, on SQLite and PostgreSQL."""

from __future__ import annotations

from alembic.autogenerate import compare_metadata
from alembic.config import Config
from alembic.migration import MigrationContext
from alembic.script import ScriptDirectory

from cloud.store.database import MIGRATIONS, Database
from cloud.store.directory import Directory
from cloud.store.tables import Table


def test_a_new_database_gets_the_declared_schema_at_the_newest_revision(db: Database) -> None:
    with db.engine.connect() as connection:
        context = MigrationContext.configure(connection)
        assert compare_metadata(context, Table.metadata) == []
        config = Config()
        config.set_main_option("script_location", str(MIGRATIONS))
        assert (
            context.get_current_revision() == ScriptDirectory.from_config(config).get_current_head()
        )


def test_opening_a_database_again_keeps_what_it_holds(db_url: str) -> None:
    first = Database(db_url)
    token = Directory(first).add_operator("ana")
    first.close()
    again = Database(db_url)  # migrations already applied: nothing to do
    try:
        assert Directory(again).authenticate(token) is not None
    finally:
        again.close()
