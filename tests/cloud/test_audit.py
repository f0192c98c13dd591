"""Every command sent or canceled, and every change to accounts, is written to an audit log
that is only ever added to: who did it, in which role, on which robot, when, and from
which address. `vest cloud audit` reads it."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import requests
import sqlalchemy as sa

from cloud.settings import Settings
from cloud.store.database import Database, engine_url
from cloud.store.directory import Directory
from engine.cli import main
from engine.clock import VirtualClock
from tests.cloud.test_api_contract import bearer

SAY = {"type": "say", "args": {"text": "hello"}}


def test_commands_sent_and_canceled_are_audited_with_who_role_robot_and_address(
    db_url: str, start_service: Callable[..., Any]
) -> None:
    clock = VirtualClock(start_s=1_800_000_000.0)
    running = start_service(Settings(db_url=db_url), clock)
    directory = running.store.directory
    ana = bearer(directory.add_operator("ana"))
    directory.add_robot("hbs2", operator="ana")
    vic = bearer(directory.add_operator("vic", role="viewer"))
    directory.grant("vic", "hbs2")
    commands = f"{running.api}/robots/hbs2/commands"
    clock.advance(60)
    sent = requests.post(commands, json={**SAY, "idempotency_key": "k1"}, headers=ana, timeout=10)
    again = requests.post(commands, json={**SAY, "idempotency_key": "k1"}, headers=ana, timeout=10)
    assert (sent.status_code, again.status_code) == (201, 200)  # one command: one entry
    assert requests.post(commands, json=SAY, headers=vic, timeout=10).status_code == 403
    clock.advance(1)
    cancel = f"{commands}/{sent.json()['id']}/cancel"
    assert requests.post(cancel, headers=ana, timeout=10).json()["state"] == "CANCELED"
    entries = directory.audit.since(1_800_000_060.0)
    assert [(e.actor, e.role, e.action, e.robot, e.client, e.at_s) for e in entries] == [
        ("ana", "operator", "send", "hbs2", "127.0.0.1", 1_800_000_060.0),
        ("ana", "operator", "cancel", "hbs2", "127.0.0.1", 1_800_000_061.0),
    ]
    assert entries[0].detail == f'say {sent.json()["id"]} {{"text": "hello"}}'


def test_account_changes_are_audited_and_read_back_as_lines_or_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    db = ["--db", f"sqlite:///{tmp_path / 'c.db'}"]
    for args in (
        ["add-account", "ana", "--role", "admin"],
        ["add-robot", "hbs2", "--operator", "ana"],
        ["add-account", "vic", "--role", "viewer", "--expires-days", "30"],
        ["grant", "vic", "hbs2"],
        ["set-role", "vic", "therapist"],
        ["rotate", "robot", "hbs2"],
        ["revoke", "operator", "vic"],
    ):
        assert main(["cloud", *args, *db]) == 0
    capsys.readouterr()
    assert main(["cloud", "audit", *db]) == 0
    lines = capsys.readouterr().out.splitlines()
    done = [line.split(": ", 1)[1] for line in lines]  # after "... from local"
    assert done[0].startswith("add-account: ana as admin, expires ")
    assert done[1:] == [
        "add-robot robot hbs2: granted to ana, never expires",
        done[2],
        "grant robot hbs2: to vic",
        "set-role: vic: viewer -> therapist",
        "rotate robot hbs2: never expires",
        "revoke: account vic",
    ]
    assert all(" (admin) from local" in line and " shell:" in line for line in lines)
    assert main(["cloud", "audit", "--json", "--since", "1h", *db]) == 0
    entries = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [e["action"] for e in entries][-2:] == ["rotate", "revoke"]
    assert entries[-1]["client"] == "local" and entries[-1]["robot"] is None
    assert main(["cloud", "audit", "--since", "2999-01-01", *db]) == 0
    assert capsys.readouterr().out == ""


def test_nothing_can_change_or_delete_an_entry_not_even_sql_by_hand(
    db_url: str, directory: Directory
) -> None:
    directory.add_operator("ana")
    engine = sa.create_engine(engine_url(db_url))
    try:
        for statement in ("UPDATE audit_log SET actor = 'nobody'", "DELETE FROM audit_log"):
            with (
                pytest.raises(sa.exc.DatabaseError, match="the audit log is append-only"),
                engine.begin() as connection,
            ):
                connection.execute(sa.text(statement))
    finally:
        engine.dispose()
    assert [e.actor for e in directory.audit.since()] == ["shell"]


def test_a_bad_since_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    Database(f"sqlite:///{tmp_path / 'c.db'}").close()
    assert (
        main(["cloud", "audit", "--since", "last week", "--db", f"sqlite:///{tmp_path}/c.db"]) == 2
    )
    assert "--since 'last week': use a date or time" in capsys.readouterr().err


def test_the_shell_s_account_is_the_operating_system_s_not_a_variable(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import os
    import pwd

    monkeypatch.setenv("LOGNAME", "mallory")
    monkeypatch.setenv("USER", "mallory")
    db = ["--db", f"sqlite:///{tmp_path / 'c.db'}"]
    assert main(["cloud", "add-account", "ana", "--role", "admin", *db]) == 0
    capsys.readouterr()
    assert main(["cloud", "audit", "--json", *db]) == 0
    actor = json.loads(capsys.readouterr().out.splitlines()[0])["actor"]
    uid = os.geteuid()
    assert actor == f"shell:{pwd.getpwuid(uid).pw_name} (uid {uid})"
