"""An admin adds operators and robots from the command line; tokens come alone on stdout."""

from __future__ import annotations

import socket
from pathlib import Path

import pytest

from cloud.services import CloudStore
from cloud.settings import Settings
from engine.cli import main
from engine.clock import EpochClock


def test_an_admin_adds_an_operator_and_a_robot_and_scripts_capture_the_tokens(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    db = f"sqlite:///{tmp_path / 'c.db'}"
    assert main(["cloud", "add-operator", "ana", "--db", db]) == 0
    operator_token = capsys.readouterr().out.strip()
    assert main(["cloud", "add-robot", "hbs2", "--operator", "ana", "--db", db]) == 0
    robot_token = capsys.readouterr().out.strip()
    store = CloudStore.open(Settings(db_url=db), EpochClock())
    try:
        assert store.directory.authenticate(operator_token).name == "ana"  # type: ignore[union-attr]
        assert store.directory.authenticate(robot_token).name == "hbs2"  # type: ignore[union-attr]
    finally:
        store.close()
    assert main(["cloud", "revoke", "robot", "hbs2", "--db", db]) == 0
    store = CloudStore.open(Settings(db_url=db), EpochClock())
    try:
        assert store.directory.authenticate(robot_token) is None
    finally:
        store.close()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["add-robot", "r", "--operator", "bob"], "no operator 'bob'"),
        (["add-operator", "a b"], "use 1 to 64 letters"),
        (["grant", "ana", "nosuch"], "no robot 'nosuch'"),
    ],
)
def test_a_mistake_is_named_and_exits_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    db = f"sqlite:///{tmp_path / 'c.db'}"
    main(["cloud", "add-operator", "ana", "--db", db])
    capsys.readouterr()
    assert main(["cloud", *args, "--db", db]) == 1
    assert message in capsys.readouterr().err


def test_a_database_that_cannot_be_opened_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["cloud", "add-operator", "ana", "--db", "sqlite:////no/such/dir/c.db"]) == 1
    assert "cannot open it" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["--workers", "2"], 2, "needs a PostgreSQL --db"),
        (["--port", "0"], 2, "--port 0: use 1..65535"),
        (["--workers", "0"], 2, "--workers 0: use 1..64"),
        (
            ["--lease-s", "nan"],
            1,
            "lease_s (--lease-s or VEST_CLOUD_LEASE_S): input should be a fi",
        ),
        (["--db", "nonsense"], 1, "use sqlite:///FILE or postgresql://"),
        (["--db", "postgresql://ana:secret@127.0.0.1:1/vest"], 1, "ana:***@"),
    ],
)
def test_a_service_that_cannot_start_says_why(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], code: int, message: str
) -> None:
    db = ["--db", f"sqlite:///{tmp_path / 'c.db'}"]
    assert main(["cloud", "serve", *db, *args]) == code
    error = capsys.readouterr().err
    assert message in error and "secret" not in error


def test_a_port_already_taken_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        db = f"sqlite:///{tmp_path / 'c.db'}"
        assert main(["cloud", "serve", "--db", db, "--port", str(port)]) == 1
    assert f"--port {port}: cannot listen there" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("variable", "value", "message"),
    [
        ("VEST_CLOUD_LEASE_S", "abc", "lease_s (--lease-s or VEST_CLOUD_LEASE_S): input should be"),
        ("VEST_CLOUD_MAX_WAIT_S", "1e999", "max_wait_s (VEST_CLOUD_MAX_WAIT_S): input should be"),
        (
            "VEST_CLOUD_LEASE",
            "3",
            "VEST_CLOUD_LEASE: no such setting (did you mean VEST_CLOUD_LEASE_S?)",
        ),
    ],
)
def test_a_setting_from_the_environment_that_cannot_be_used_is_named(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    variable: str,
    value: str,
    message: str,
) -> None:
    monkeypatch.setenv(variable, value)
    assert main(["cloud", "add-operator", "ana", "--db", f"sqlite:///{tmp_path / 'c.db'}"]) == 1
    assert message in capsys.readouterr().err
