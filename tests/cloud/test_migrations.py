"""The migrations build exactly the schema the code declares, on SQLite and PostgreSQL, and
carry what a database holds from one schema to the next (and back)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import sqlalchemy as sa
from alembic import command
from alembic.autogenerate import compare_metadata
from alembic.migration import MigrationContext
from alembic.script import ScriptDirectory

from cloud.store.database import Database, alembic_config, engine_url
from cloud.store.directory import Directory
from cloud.store.tables import Table
from cloud.store.telemetry import Telemetry
from cloud.store.tokens import digest
from engine.cli import main
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


def test_a_database_a_newer_vest_upgraded_is_named_in_one_line(
    db_url: str, capsys: pytest.CaptureFixture[str]
) -> None:
    Database(db_url).close()
    engine = sa.create_engine(engine_url(db_url))
    with engine.begin() as connection:
        connection.execute(sa.text("UPDATE alembic_version SET version_num = '0099_future'"))
    engine.dispose()
    assert main(["cloud", "add-operator", "ana", "--db", db_url]) == 1
    err = capsys.readouterr().err
    assert "'0099_future') was made by a newer vest than this one; update vest" in err
    assert "Traceback" not in err


def test_a_database_recorded_at_two_revisions_at_once_is_named_in_one_line(
    db_url: str, capsys: pytest.CaptureFixture[str]
) -> None:
    Database(db_url).close()
    engine = sa.create_engine(engine_url(db_url))
    with engine.begin() as connection:
        connection.execute(sa.text("INSERT INTO alembic_version VALUES ('0001_other')"))
    engine.dispose()
    assert main(["cloud", "add-operator", "ana", "--db", db_url]) == 1
    err = capsys.readouterr().err
    assert "its schema is recorded as at 2 revisions at once" in err
    assert "Traceback" not in err


@pytest.mark.realtime
def test_commands_opening_a_new_sqlite_database_at_once_all_succeed(tmp_path: Path) -> None:
    opener = "from cloud.store.database import Database; import sys; Database(sys.argv[1]).close()"
    for round_ in range(4):
        url = f"sqlite:///{tmp_path / f'new{round_}.db'}"
        started = [
            subprocess.Popen([sys.executable, "-c", opener, url], stderr=subprocess.PIPE)
            for _ in range(3)
        ]
        for process in started:
            _, err = process.communicate(timeout=60)
            assert process.returncode == 0, err.decode()


def test_accounts_made_before_roles_become_operators_whose_tokens_do_not_expire(
    db_url: str, clock: VirtualClock
) -> None:
    engine = sa.create_engine(engine_url(db_url))
    with engine.begin() as connection:  # a database made before roles and expiry
        command.upgrade(alembic_config(connection), "0002")
        connection.execute(
            sa.text(
                "INSERT INTO operators (id, name, token_digest, revoked)"
                f" VALUES (1, 'ana', '{digest('old-token')}', false)"
            )
        )
    db = Database(db_url)  # brought up to date on opening
    try:
        ana = Directory(db, clock).authenticate("old-token")
        assert ana is not None and (ana.role, ana.expires_at_s) == ("operator", None)
        Directory(db, clock).set_role("ana", "viewer")  # an entry in the new audit log
    finally:
        db.close()
    with engine.begin() as connection:  # and back: the audit log (and its guard) go
        command.downgrade(alembic_config(connection), "0002")
        assert sa.inspect(connection).has_table("audit_log") is False
        assert connection.execute(sa.text("SELECT name FROM operators")).scalars().all() == ["ana"]
    engine.dispose()
