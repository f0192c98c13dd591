"""The robot's cloud link tells the truth: an operator's cancel stops the robot, a damaged
record of finished commands is named and never makes a command run twice, and telemetry
is what the scheduler committed, its failures counted."""

from __future__ import annotations

import http.server
import json
import logging
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import requests

from cloud.services import CloudStore
from cloud.settings import Settings
from cloud.store.ledger import CANCELED, FAILED
from engine.cli import main
from engine.clock import VirtualClock
from engine.services.cloud_link import CloudLink
from engine.services.done_commands import DoneCommands
from engine.session.events import Heard, KeyChanged
from engine.session.stream import SessionStream

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[2]
A_LONG_SENTENCE = " ".join(["one two three four five"] * 8)  # 40 words: 12 s at 0.3 s each


def service(
    tmp_path: Path, start_service: Callable[..., Any], **settings: float
) -> tuple[str, CloudStore, int, Path]:
    """A service on loopback with one robot; (url, store, the robot's id, its token file)."""
    chosen: dict[str, Any] = {"max_wait_s": 1.0, "recheck_s": 0.2, **settings}
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", **chosen))
    store = running.store
    store.directory.add_operator("ana")
    token_file = tmp_path / "robot.token"
    token_file.write_text(store.directory.add_robot("hbs2", operator="ana") + "\n")
    robot = store.directory.authenticate(token_file.read_text().strip())
    assert robot is not None
    return running.url, store, robot.id, token_file


def quiet(tmp_path: Path, seconds: float) -> Path:
    path = tmp_path / "quiet.yaml"
    path.write_text(f"duration_s: {seconds}\nevents: []\n")
    return path


def test_an_operator_s_cancel_stops_the_tree_carrying_the_command_out(
    tmp_path: Path, start_service: Callable[..., Any], start_robot: Callable[..., Any]
) -> None:
    url, store, robot_id, token_file = service(tmp_path, start_service)
    command, _ = store.ledger.submit(robot_id, "say", {"text": A_LONG_SENTENCE})
    robot = start_robot(url, token_file, quiet(tmp_path, 8), ["trees/iot_command.yaml"])

    robot.until(lambda a: a["action"] == "say")  # it has begun the long sentence
    store.ledger.cancel(robot_id, command.id)
    robot.finish()

    [ended] = [e for e in robot.events if e["event"] == "outcome"]
    assert (ended["action"], ended["outcome"]) == ("say", "cut")
    assert ended["why"] == "canceled by the operator"
    # well before the 12 s sentence would have ended (a progress report comes every 2 s;
    # a loaded machine takes longer, never as long as the sentence)
    assert ended["t"] - ended["started"] < 6.0
    [report] = [a for a in robot.actions if a["action"] == "report"]
    assert report["args"]["result"] == {"error": "canceled by the operator"}
    finished = store.ledger.get(robot_id, command.id)  # that report is not sent: it ended
    assert finished is not None and finished.state == CANCELED and finished.result is None


def test_a_damaged_record_is_kept_aside_and_a_command_delivered_again_is_not_run_again(
    tmp_path: Path,
    start_service: Callable[..., Any],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    url, store, robot_id, token_file = service(tmp_path, start_service, lease_s=0.5)
    done = tmp_path / "robot.token.done.json"
    done.write_text('{"cmd-1": {"status": "SUCC')  # cut off mid-write by a full disk
    command, _ = store.ledger.submit(robot_id, "say", {"text": "hello twice?"})
    taken = store.ledger.claim_next(robot_id)  # delivered once before the robot restarted
    assert taken is not None and taken.deliveries == 1

    monkeypatch.chdir(ROOT)
    args = ["run", "--trees", "trees/iot_command.yaml", "--scenario", str(quiet(tmp_path, 4))]
    args += ["--speech", "text", "--json", "--cloud", url, "--token-file", str(token_file)]
    with caplog.at_level(logging.ERROR):
        assert main(args) == 0

    assert "hello twice?" not in capsys.readouterr().out  # never said, rather than twice
    finished = store.ledger.get(robot_id, command.id)
    # delivered again at least once (once more if the 0.5 s lease ran out on a loaded
    # machine before the robot's report came): never carried out, always reported failed
    assert finished is not None and finished.state == FAILED and finished.deliveries >= 2
    assert "record of finished commands was damaged" in finished.result["error"]
    aside = tmp_path / "robot.token.done.json.damaged"
    assert aside.read_text() == '{"cmd-1": {"status": "SUCC'  # kept for whoever looks into it
    assert f"kept aside as {aside}" in caplog.text


class FailingHttp(requests.Session):
    """A session whose every request fails as an unreachable service does."""

    def __init__(self) -> None:
        super().__init__()
        self.posts = 0

    def post(self, *args: Any, **kwargs: Any) -> requests.Response:  # type: ignore[override]
        self.posts += 1
        raise requests.ConnectionError("connection refused")


def test_telemetry_is_what_the_scheduler_committed_and_its_failures_are_counted(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    clock = VirtualClock()
    http = FailingHttp()
    link = CloudLink("http://127.0.0.1:9", "t", clock, done_file=tmp_path / "d.json", http=http)
    stream = SessionStream(clock)
    link.telemetry_from(stream)
    assert link.push_telemetry()  # nothing committed yet: nothing to push
    stream.publish(KeyChanged(1.0, "/sensors/force/left_n", 6.5, "6.5", False, "force poller"))
    stream.publish(KeyChanged(1.0, "/vars/mood", "happy", '"happy"', False, "trees"))
    stream.publish(Heard(1.0, "hello"))
    assert link.telemetry.take() == {"/sensors/force/left_n": 6.5}  # sensors and devices only

    with caplog.at_level(logging.WARNING):
        assert not link.push_telemetry()
        assert not link.push_telemetry()
    assert (http.posts, link.telemetry_failures) == (2, 2)
    assert caplog.text.count("telemetry could not be pushed") == 1  # once per streak


@pytest.mark.parametrize(
    "damaged",
    [
        "[" * 100_000 + "]" * 100_000,
        "",
        "[1, 2]",
        '{"cmd-1": "done"}',
        '{"cmd-1": {"status": "X"}}',
        "\x00\xff",
    ],
)
def test_any_damaged_record_of_finished_commands_is_set_aside(tmp_path: Path, damaged: str) -> None:
    path = tmp_path / "robot.token.done.json"
    path.write_text(damaged, encoding="utf-8", errors="surrogateescape")
    done = DoneCommands(path)
    assert done.damaged == tmp_path / "robot.token.done.json.damaged"
    assert done.get("cmd-1") is None and not path.exists()


class CaptivePortal(http.server.BaseHTTPRequestHandler):
    """Answers the robot's first polls with a portal's page (200, HTML) and JSON nested too
    deep to read, then one command (with a 1 ms lease), nothing, the portal again, then
    nothing more; answers the robot's progress with a JSON list (not the command); takes
    any report."""

    polls = 0
    progress = 0
    reports: list[dict[str, Any]] = []
    PORTAL = b"<html><body>Welcome! Log in to the clinic wifi</body></html>"

    def do_GET(self) -> None:
        CaptivePortal.polls += 1
        if CaptivePortal.polls in (1, 5):
            self._send(200, self.PORTAL)
        elif CaptivePortal.polls == 2:
            self._send(200, b"[" * 100_000 + b"]" * 100_000, "application/json")
        elif CaptivePortal.polls == 3:
            command = {"id": "c-1", "type": "say", "args": {"text": "through the portal"}}
            lease = {"lease_s": 0.001}  # a service set up wrong: the robot must not storm it
            self._send(200, json.dumps({**command, **lease}).encode(), "application/json")
        else:
            self._send(204, b"")

    def do_POST(self) -> None:
        length = int(self.headers.get("content-length", "0"))
        body = self.rfile.read(length)
        if self.path.endswith("/result"):
            CaptivePortal.reports.append(json.loads(body))
        if self.path.endswith("/progress"):
            CaptivePortal.progress += 1
            self._send(200, b"[]", "application/json")
            return
        self._send(200, b"{}", "application/json")

    def _send(self, code: int, body: bytes, kind: str = "text/html") -> None:
        self.send_response(code)
        self.send_header("content-type", kind)
        self.send_header("content-length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: Any) -> None:
        """Quiet."""


def test_a_reply_that_is_not_a_command_is_retried_and_the_robot_keeps_taking_commands(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), CaptivePortal)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    token = tmp_path / "robot.token"
    token.write_text("t0ken\n")
    monkeypatch.chdir(ROOT)
    url = f"http://127.0.0.1:{server.server_address[1]}"
    args = ["run", "--trees", "trees/iot_command.yaml", "--scenario", str(quiet(tmp_path, 5))]
    args += ["--speech", "text", "--json", "--cloud", url, "--token-file", str(token)]
    try:
        with caplog.at_level(logging.WARNING):
            assert main(args) == 0
    finally:
        server.shutdown()
    said = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert any(line.get("args", {}).get("text") == "through the portal" for line in said)
    assert CaptivePortal.reports == [{"status": "SUCCEEDED", "result": None}]
    # its odd answers did not stop the robot reporting, at most ten times a second (a say
    # of three words takes about a second; at a third of the lease it would be thousands)
    assert 1 <= CaptivePortal.progress <= 30
    assert CaptivePortal.polls > 5  # nor polling
    assert caplog.text.count("is not a command") == 2  # once a streak


def test_a_robot_revoked_while_its_long_poll_waits_is_answered_401_and_takes_nothing(
    tmp_path: Path, start_service: Callable[..., Any]
) -> None:
    url, store, robot_id, token_file = service(
        tmp_path, start_service, max_wait_s=30.0, token_cache_s=0.0
    )
    headers = {"Authorization": f"Bearer {token_file.read_text().strip()}"}
    polling: list[requests.Response] = []
    poll = threading.Thread(
        target=lambda: polling.append(
            requests.get(f"{url}/api/v1/robot/commands/next?wait_s=20", headers=headers)
        )
    )
    poll.start()
    assert store.telemetry.wait_until_polling(robot_id, timeout_s=30)  # it waits
    store.directory.revoke("robot", "hbs2")
    command, _ = store.ledger.submit(robot_id, "say", {"text": "for a revoked robot"})
    poll.join(timeout=30)
    assert [answer.status_code for answer in polling] == [401]
    still = store.ledger.get(robot_id, command.id)
    assert still is not None and still.state == "QUEUED"  # never taken
