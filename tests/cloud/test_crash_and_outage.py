"""The service killed with SIGKILL and started again loses no command and makes no robot
carry one out twice; a robot whose service went away keeps behaving and catches up.

The service and the robot run as real processes (`vest cloud serve`, `vest run --cloud` on
the simulated vest); a test waits on what they print and on the service's live stream,
never on a timer.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import requests

from engine.cli import main
from engine.services.cloud_link import DoneCommands

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[2]
VEST = [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


class ServiceProcess:
    """`vest cloud serve` in its own process, on one database and port across restarts."""

    def __init__(self, db_url: str) -> None:
        self.db_url = db_url
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.process: subprocess.Popen[str] | None = None

    def start(self) -> None:
        line = [*VEST, "cloud", "serve", "--db", self.db_url, "--port", str(self.port)]
        self.process = subprocess.Popen(
            [*line, "--lease-s", "1"], cwd=ROOT, stderr=subprocess.PIPE, text=True
        )
        assert self.process.stderr is not None
        for text in self.process.stderr:  # blocks until the server says it listens
            if "Application startup complete" in text:
                break
        else:
            raise AssertionError(f"vest cloud serve ended: {self.process.wait()}")
        stderr = self.process.stderr
        threading.Thread(target=lambda: stderr.read(), daemon=True).start()

    def kill(self) -> None:
        """SIGKILL: no shutdown, no flush, nothing the service can do about it."""
        assert self.process is not None
        os.kill(self.process.pid, signal.SIGKILL)
        self.process.wait()

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.kill()


class Operator:
    def __init__(self, service: ServiceProcess, token: str) -> None:
        self.service = service
        self.headers = {"Authorization": f"Bearer {token}"}

    def send(self, text: str) -> str:
        return self.send_command("say", {"text": text}, key=text)

    def send_command(self, kind: str, args: dict[str, Any], key: str | None = None) -> str:
        answer = requests.post(
            f"{self.service.url}/api/v1/robots/hbs2/commands",
            json={"type": kind, "args": args, "idempotency_key": key},
            headers=self.headers,
            timeout=10,
        )
        assert answer.status_code == 201, answer.text
        return str(answer.json()["id"])

    def command(self, command_id: str) -> dict[str, Any]:
        answer = requests.get(
            f"{self.service.url}/api/v1/robots/hbs2/commands/{command_id}",
            headers=self.headers,
            timeout=10,
        )
        assert answer.status_code == 200, answer.text
        return dict(answer.json())

    def until_finished(self, command_id: str) -> dict[str, Any]:
        """The command once it ended, watched on the live stream (read timeout: 30 s)."""
        return self.until_state(command_id, "SUCCEEDED", "FAILED", "TIMED_OUT", "CANCELED")

    def until_state(self, command_id: str, *states: str) -> dict[str, Any]:
        """The command once it is in one of ``states``, watched on the live stream."""
        with requests.get(
            f"{self.service.url}/api/v1/events", headers=self.headers, stream=True, timeout=30
        ) as stream:
            name = ""
            for line in stream.iter_lines(chunk_size=1, decode_unicode=True):
                if line.startswith("event:"):
                    name = line.removeprefix("event:").strip()
                elif line.startswith("data:") and name == "command":
                    command = json.loads(line.removeprefix("data:"))
                    if command["id"] == command_id and command["state"] in states:
                        return dict(command)
        raise AssertionError(f"the stream ended before {command_id} was {states}")


@pytest.fixture
def setup(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Iterator[dict[str, Any]]:
    db_url = f"sqlite:///{tmp_path / 'cloud.db'}"
    assert main(["cloud", "add-operator", "ana", "--db", db_url]) == 0
    operator_token = capsys.readouterr().out.strip()
    assert main(["cloud", "add-robot", "hbs2", "--operator", "ana", "--db", db_url]) == 0
    token_file = tmp_path / "robot.token"
    token_file.write_text(capsys.readouterr().out)
    service = ServiceProcess(db_url)
    service.start()
    yield {"service": service, "operator": Operator(service, operator_token), "token": token_file}
    service.stop()


def robot_claims(service: ServiceProcess, token_file: Path) -> dict[str, Any]:
    answer = requests.get(
        f"{service.url}/api/v1/robot/commands/next",
        headers={"Authorization": f"Bearer {token_file.read_text().strip()}"},
        timeout=10,
    )
    assert answer.status_code == 200, answer.text
    return dict(answer.json())


def test_a_killed_service_loses_no_command_and_none_is_carried_out_twice(
    setup: dict[str, Any], tmp_path: Path, start_robot: Callable[..., Any]
) -> None:
    service, operator, token_file = setup["service"], setup["operator"], setup["token"]
    done = DoneCommands(Path(f"{token_file}.done.json"))
    alpha, bravo, charlie, delta = (
        operator.send(w) for w in ("alpha", "bravo", "charlie", "delta")
    )
    # the robot carried out alpha and reported it
    assert robot_claims(service, token_file)["id"] == alpha
    requests.post(
        f"{service.url}/api/v1/robot/commands/{alpha}/result",
        json={"status": "SUCCEEDED", "result": {"said": "alpha"}},
        headers={"Authorization": f"Bearer {token_file.read_text().strip()}"},
        timeout=10,
    ).raise_for_status()
    # it carried out bravo, but the report never arrived; it took charlie and then died
    assert robot_claims(service, token_file)["id"] == bravo
    done.add(bravo, {"status": "SUCCEEDED", "result": {"said": "bravo"}})
    assert robot_claims(service, token_file)["id"] == charlie

    service.kill()
    service.start()

    assert operator.command(alpha)["state"] == "SUCCEEDED"
    assert operator.command(alpha)["result"] == {"said": "alpha"}
    assert {operator.command(c)["state"] for c in (bravo, charlie)} <= {"IN_PROGRESS", "QUEUED"}
    assert operator.command(delta)["state"] == "QUEUED"

    (tmp_path / "quiet.yaml").write_text("duration_s: 60\nevents: []\n")
    robot = start_robot(
        service.url, token_file, tmp_path / "quiet.yaml", ["trees/iot_command.yaml"]
    )
    try:
        for command in (bravo, charlie, delta):
            assert operator.until_finished(command)["state"] == "SUCCEEDED"
    finally:
        robot.process.send_signal(signal.SIGTERM)
    robot.finish()
    assert sorted(robot.said()) == ["charlie", "delta"]  # bravo was answered, not said again
    assert operator.command(bravo)["result"] == {"said": "bravo"}
    assert operator.command(bravo)["deliveries"] == 2


def test_a_robot_whose_service_went_away_keeps_behaving_and_catches_up(
    setup: dict[str, Any], tmp_path: Path, start_robot: Callable[..., Any]
) -> None:
    service, operator, token_file = setup["service"], setup["operator"], setup["token"]
    scenario = tmp_path / "pats.yaml"
    scenario.write_text(
        "duration_s: 120\nevents:\n"
        + "".join(f"  - {{at: {t}, touch: {{pad: 3, seconds: 0.3}}}}\n" for t in range(5, 120, 5))
    )
    robot = start_robot(
        service.url, token_file, scenario, ["trees/iot_command.yaml", "trees/touch_thanks.yaml"]
    )
    try:
        before = operator.send("before the outage")
        assert operator.until_finished(before)["state"] == "SUCCEEDED"

        service.kill()  # the robot's link to its service is gone
        robot.until(lambda a: a["args"].get("text") == "before the outage")
        robot.until(lambda a: a["tree"] == "touch_thanks")  # maybe just before the cut
        answered = robot.until(lambda a: a["tree"] == "touch_thanks")  # 5 s later: after it
        assert answered["args"]["text"] == "Thank you"  # the robot still answers a pat

        service.start()
        after = operator.send("after the outage")
        assert operator.until_finished(after)["state"] == "SUCCEEDED"
    finally:
        robot.process.send_signal(signal.SIGTERM)
    robot.finish()
    assert robot.said().count("before the outage") == 1
    assert robot.said().count("after the outage") == 1


def test_a_robot_takes_one_command_at_a_time_so_a_waiting_one_can_still_be_canceled(
    setup: dict[str, Any], tmp_path: Path, start_robot: Callable[..., Any]
) -> None:
    service, operator, token_file = setup["service"], setup["operator"], setup["token"]
    quiet = tmp_path / "quiet.yaml"
    quiet.write_text("duration_s: 60\nevents: []\n")
    robot = start_robot(service.url, token_file, quiet, ["trees/iot_command.yaml"])
    try:
        slow = operator.send_command("move", {"joint": "neck", "angle_deg": 50, "speed_dps": 10})
        operator.until_state(slow, "IN_PROGRESS")  # the neck turns for 5 s
        waiting = operator.send("not now")
        assert operator.command(waiting)["state"] == "QUEUED"  # not taken while busy
        canceled = requests.post(
            f"{service.url}/api/v1/robots/hbs2/commands/{waiting}/cancel",
            headers=operator.headers,
            timeout=10,
        ).json()
        assert canceled["state"] == "CANCELED"
        finished = operator.until_finished(slow)
        # five seconds of turning on a one-second lease: extended, never delivered again
        assert (finished["state"], finished["deliveries"]) == ("SUCCEEDED", 1)
        after = operator.send("after the move")
        assert operator.until_finished(after)["state"] == "SUCCEEDED"
    finally:
        robot.process.send_signal(signal.SIGTERM)
    robot.finish()
    assert robot.said() == ["after the move"]  # the canceled one was never said
