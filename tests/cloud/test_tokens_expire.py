"""Tokens expire (people's after 90 days unless their admin says, robots' never unless
said) and can be rotated: the fresh one works, the old one stops within the token cache
time. Time is the service's injected clock, moved by the test."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import requests

from cloud.services import CloudStore
from cloud.settings import Settings
from cloud.store.directory import Directory
from engine.cli import main
from engine.clock import EpochClock, VirtualClock
from engine.errors import ConfigError
from tests.cloud.test_api_contract import bearer

DAY_S = 86_400.0


def test_a_person_s_token_works_90_days_and_is_then_refused_as_expired(
    tmp_path: Path, start_service: Callable[..., Any]
) -> None:
    clock = VirtualClock(start_s=1_800_000_000.0)  # 2027-01-15
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"), clock)
    ana = bearer(running.store.directory.add_operator("ana"))
    robot = bearer(running.store.directory.add_robot("hbs2", operator="ana"))
    clock.advance(90 * DAY_S - 1)
    assert requests.get(f"{running.api}/robots", headers=ana, timeout=10).status_code == 200
    clock.advance(1)  # expired the moment it is due, though the cache still knows it
    refused = requests.get(f"{running.api}/robots", headers=ana, timeout=10)
    assert refused.status_code == 401
    assert refused.json()["detail"] == (
        "this token expired on 2027-04-15 08:00 UTC; ask an admin for a new one "
        "(vest cloud rotate operator ana)"
    )
    assert refused.headers["WWW-Authenticate"] == "Bearer"
    # the robot's token has no expiry unless its admin gave one
    clock.advance(3650 * DAY_S)
    pushed = requests.post(
        f"{running.api}/robot/telemetry", json={"values": {}}, headers=robot, timeout=10
    )
    assert pushed.status_code == 204


def test_an_expiry_chosen_on_adding_holds_for_people_and_robots(
    directory: Directory, clock: VirtualClock
) -> None:
    ana = directory.add_operator("ana", expires_days=1)
    robot = directory.add_robot("hbs2", operator="ana", expires_days=30)
    never = directory.add_operator("kiosk", expires_days=None)
    clock.advance(DAY_S)
    assert directory.authenticate(ana) is None
    assert directory.holder(ana) is not None  # known, and expired: the 401 says so
    assert directory.authenticate(robot) is not None
    clock.advance(29 * DAY_S)
    assert directory.authenticate(robot) is None
    assert directory.authenticate(never) is not None


@pytest.mark.parametrize("days", [0, -1, 3651])
def test_an_expiry_out_of_range_is_refused(directory: Directory, days: float) -> None:
    with pytest.raises(ConfigError, match="--expires-days"):
        directory.add_operator("ana", expires_days=days)


def test_a_rotated_token_replaces_the_old_one_within_the_cache_time(
    tmp_path: Path, start_service: Callable[..., Any]
) -> None:
    clock = VirtualClock(start_s=1_800_000_000.0)
    running = start_service(
        Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", token_cache_s=5.0), clock
    )
    directory = running.store.directory
    old = bearer(directory.add_operator("ana", expires_days=1))
    assert requests.get(f"{running.api}/robots", headers=old, timeout=10).status_code == 200
    new = bearer(directory.rotate("operator", "ana", expires_days=90))
    assert requests.get(f"{running.api}/robots", headers=new, timeout=10).status_code == 200
    clock.advance(5.1)
    assert requests.get(f"{running.api}/robots", headers=old, timeout=10).status_code == 401
    clock.advance(2 * DAY_S)  # past the old expiry: the new token has its own
    assert requests.get(f"{running.api}/robots", headers=new, timeout=10).status_code == 200


def test_rotate_on_the_command_line_prints_the_fresh_token_alone(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    db = f"sqlite:///{tmp_path / 'c.db'}"
    main(["cloud", "add-account", "ana", "--db", db])
    main(["cloud", "add-robot", "hbs2", "--operator", "ana", "--expires-days", "7", "--db", db])
    old = capsys.readouterr().out.split()[1]
    assert main(["cloud", "rotate", "robot", "hbs2", "--db", db]) == 0
    fresh = capsys.readouterr().out
    assert fresh.count("\n") == 1 and len(fresh.strip()) == 43
    store = CloudStore.open(Settings(db_url=db), EpochClock())
    try:
        assert store.directory.authenticate(old) is None
        robot = store.directory.authenticate(fresh.strip())
        assert robot is not None and robot.expires_at_s is None  # a robot's default: never
    finally:
        store.close()


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["rotate", "operator", "bob"], 1, "no operator 'bob'"),
        (["rotate", "robot", "hbs2", "--expires-days", "soon"], 2, "give a number of days"),
        (["add-account", "cara", "--expires-days", "0"], 2, "use more than 0"),
        (["add-account", "cara", "--role", "boss"], 1, "no role 'boss'; use one of admin"),
        (["set-role", "ana", "viewr"], 1, "no role 'viewr' (did you mean 'viewer'?)"),
        (["set-role", "bob", "viewer"], 1, "no operator 'bob'"),
    ],
)
def test_a_mistake_about_tokens_or_roles_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], code: int, message: str
) -> None:
    db = f"sqlite:///{tmp_path / 'c.db'}"
    main(["cloud", "add-operator", "ana", "--db", db])
    capsys.readouterr()
    if code == 2:  # refused by the command line's parser
        with pytest.raises(SystemExit) as exited:
            main(["cloud", *args, "--db", db])
        assert exited.value.code == 2
    else:
        assert main(["cloud", *args, "--db", db]) == code
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
