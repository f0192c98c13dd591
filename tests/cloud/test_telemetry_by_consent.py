"""A robot tells the cloud a child's sensor readings only when their guardian consented
to telemetry; the robot's own device states are sent either way (the operator sees a
robot that works)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from cloud.settings import Settings
from engine.cli import main
from engine.privacy.consent_gate import RESULT_WITHHELD as WITHHELD

ROOT = Path(__file__).resolve().parents[2]
SQUEEZES = """\
duration_s: 2.5
events:
  - {at: 0.2, squeeze: {left_n: 9, right_n: 9, seconds: 2.0}}
"""


def session(tmp_path: Path, start_service: Callable[..., Any], person: str) -> tuple[set[str], Any]:
    """A short session of ``person`` with the cloud, an operator asking the robot for its
    force readings: (the telemetry keys the service holds, that command as it ended)."""
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"))
    store = running.store
    store.directory.add_operator("ana")
    token = tmp_path / "robot.token"
    token.write_text(store.directory.add_robot("hbs2", operator="ana") + "\n")
    robot = store.directory.authenticate(token.read_text().strip())
    read, _ = store.ledger.submit(robot.id, "read", {"sensor": "force"})
    scenario = tmp_path / "squeezes.yaml"
    scenario.write_text(SQUEEZES)
    args = ["run", "--trees", "trees/hug.yaml", "trees/iot_command.yaml"]
    args += ["--scenario", str(scenario), "--speech", "text"]
    args += ["--cloud", running.url, "--token-file", str(token), "--person", person]
    assert main(args) == 0
    return set(store.telemetry.latest(robot.id)), store.ledger.get(robot.id, read.id)


@pytest.fixture(autouse=True)
def here(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def test_without_consent_only_the_robot_s_devices_are_sent(
    tmp_path: Path, start_service: Callable[..., Any], capsys: pytest.CaptureFixture[str]
) -> None:
    keys, read = session(tmp_path, start_service, "kid-17")
    assert "kid-17: no consent record" in capsys.readouterr().err
    assert keys and all(key.startswith("/devices/") for key in keys)
    assert read.state == "FAILED"  # nor through an operator's read command
    assert read.result == {"error": WITHHELD}


def test_with_consent_to_telemetry_the_sensor_readings_are_sent(
    tmp_path: Path, start_service: Callable[..., Any], consenting
) -> None:
    consenting("kid-17", "sensors", "cloud_telemetry")
    keys, read = session(tmp_path, start_service, "kid-17")
    assert "/sensors/force/left_n" in keys
    assert read.state == "SUCCEEDED" and "/sensors/force/left_n" in read.result
