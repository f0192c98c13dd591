"""A robot on the simulated vest takes a command from the cloud, carries it out once, and
reports it; it keeps behaving while the service is away."""

from __future__ import annotations

import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from cloud.services import CloudStore
from cloud.settings import Settings
from cloud.store.ledger import SUCCEEDED
from engine.cli import main
from engine.services.done_commands import DoneCommands
from tests.cloud.conftest import Robot

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def cloud(tmp_path: Path, start_service: Callable[..., Any]) -> tuple[str, CloudStore]:
    settings = Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", max_wait_s=1.0, recheck_s=0.2)
    running = start_service(settings)
    return running.url, running.store


@pytest.mark.realtime
def test_vest_run_carries_out_a_say_from_the_cloud_and_reports_it(
    cloud: tuple[str, CloudStore], tmp_path: Path, start_robot: Callable[..., Robot]
) -> None:
    url, store = cloud
    store.directory.add_operator("ana")
    token_file = tmp_path / "robot.token"
    token_file.write_text(store.directory.add_robot("hbs2", operator="ana") + "\n")
    robot_id = store.directory.authenticate(token_file.read_text().strip()).id  # type: ignore[union-attr]
    command, _ = store.ledger.submit(robot_id, "say", {"text": "hello from the page"})
    (tmp_path / "long.yaml").write_text("duration_s: 600\nevents: []\n")
    robot = start_robot(url, token_file, tmp_path / "long.yaml", ["trees/iot_command.yaml"])
    robot.until(lambda action: action["action"] == "report")  # however loaded the machine
    robot.process.send_signal(signal.SIGINT)  # its report is sent before it stops
    robot.finish()
    finished = store.ledger.get(robot_id, command.id)
    assert finished is not None and finished.state == SUCCEEDED
    assert DoneCommands(tmp_path / "robot.token.done.json").get(command.id) is not None


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--cloud", "http://x"], "go together"),
        (["--cloud", "ftp://x", "--token-file", "t"], "http:// or https://"),
        (["--cloud", "http://", "--token-file", "t"], "give the service's http://"),
        (["--cloud", "http://[::1", "--token-file", "t"], "give the service's http://"),
        (["--cloud", "http://127.0.0.1:99999", "--token-file", "t"], "give the service's"),
        (["--cloud", "http://x", "--token-file", "/no/such/token"], "file not found"),
        (["--cloud", "http://x", "--token-file", "/dev/zero"], "(name a token file)"),
        (["--cloud", "http://x", "--token-file", "/etc"], "/etc:1:1: is a folder, not a file"),
    ],
)
def test_wrong_cloud_options_are_named(
    args: list[str],
    message: str,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(ROOT)
    assert main(["run", "--speech", "text", *args]) in (1, 2)
    assert message in capsys.readouterr().err


def test_finished_commands_are_remembered_across_a_restart(tmp_path: Path) -> None:
    done = DoneCommands(tmp_path / "done.json")
    done.add("c-1", {"status": "SUCCEEDED", "result": {"said": "hi"}})
    again = DoneCommands(tmp_path / "done.json")  # the robot restarted
    assert again.get("c-1") == {"status": "SUCCEEDED", "result": {"said": "hi"}}
    assert again.get("c-2") is None


def test_a_command_the_operator_canceled_is_remembered_not_taken_for_damage(
    tmp_path: Path,
) -> None:
    done = DoneCommands(tmp_path / "done.json")
    done.add("c-1", {"status": "CANCELED", "result": None})  # as the link keeps a cancel
    again = DoneCommands(tmp_path / "done.json")  # the robot restarted
    assert again.damaged is None
    assert again.get("c-1") == {"status": "CANCELED", "result": None}
