"""The /api/v1 contract, end to end against a real uvicorn server on loopback."""

from __future__ import annotations

import socket
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import requests
import uvicorn

from cloud.app import API, create_app
from cloud.services import CloudStore
from cloud.settings import Settings
from engine.clock import RealClock


@dataclass
class Service:
    url: str
    store: CloudStore
    operator: dict[str, str]
    robot: dict[str, str]
    other_robot: dict[str, str]
    stranger: dict[str, str]


def bearer(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


def listening_socket() -> socket.socket:
    """A socket already listening on a free loopback port: requests queue on it until the
    server accepts them, so the test need not wait for the server to start."""
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    sock.listen(64)
    return sock


@pytest.fixture
def service(tmp_path: Path) -> Iterator[Service]:
    settings = Settings(db_url=f"sqlite:///{tmp_path / 'cloud.db'}", max_wait_s=10.0, recheck_s=0.5)
    store = CloudStore.open(settings, RealClock())
    ana = store.directory.add_operator("ana")
    robot = store.directory.add_robot("hbs2", operator="ana")
    other = store.directory.add_robot("hbs3", operator="ana")
    stranger = store.directory.add_operator("zed")
    sock = listening_socket()
    port = sock.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(create_app(settings, store=store), log_level="warning"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    yield Service(
        f"http://127.0.0.1:{port}{API}",
        store,
        bearer(ana),
        bearer(robot),
        bearer(other),
        bearer(stranger),
    )
    server.should_exit = True
    thread.join(timeout=10)
    sock.close()
    store.close()


def test_an_operator_sends_a_say_and_the_robot_carries_it_out(service: Service) -> None:
    robots = requests.get(f"{service.url}/robots", headers=service.operator, timeout=10).json()
    assert [r["name"] for r in robots] == ["hbs2", "hbs3"]
    sent = requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hello"}},
        headers=service.operator,
        timeout=10,
    )
    assert sent.status_code == 201 and sent.json()["state"] == "QUEUED"
    command = sent.json()
    claimed = requests.get(
        f"{service.url}/robot/commands/next?wait_s=1", headers=service.robot, timeout=10
    )
    assert claimed.status_code == 200 and claimed.json()["state"] == "IN_PROGRESS"
    reported = requests.post(
        f"{service.url}/robot/commands/{command['id']}/result",
        json={"status": "SUCCEEDED", "result": {"said": "hello"}},
        headers=service.robot,
        timeout=10,
    )
    assert reported.status_code == 200
    again = requests.post(
        f"{service.url}/robot/commands/{command['id']}/result",
        json={"status": "SUCCEEDED", "result": {"said": "hello"}},
        headers=service.robot,
        timeout=10,
    )
    assert again.status_code == 200 and again.json()["version"] == reported.json()["version"]
    different = requests.post(
        f"{service.url}/robot/commands/{command['id']}/result",
        json={"status": "FAILED", "result": None},
        headers=service.robot,
        timeout=10,
    )
    assert different.status_code == 409
    seen = requests.get(
        f"{service.url}/robots/hbs2/commands/{command['id']}", headers=service.operator, timeout=10
    )
    assert seen.json()["state"] == "SUCCEEDED" and seen.json()["result"] == {"said": "hello"}


def test_a_waiting_robot_gets_a_command_sent_while_it_waits(service: Service) -> None:
    got: list[requests.Response] = []
    waiter = threading.Thread(
        target=lambda: got.append(
            requests.get(
                f"{service.url}/robot/commands/next?wait_s=10", headers=service.robot, timeout=20
            )
        )
    )
    waiter.start()
    requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hi"}},
        headers=service.operator,
        timeout=10,
    )
    waiter.join(timeout=20)
    assert got and got[0].status_code == 200 and got[0].json()["args"] == {"text": "hi"}


def test_no_command_within_the_wait_is_204(service: Service) -> None:
    answer = requests.get(
        f"{service.url}/robot/commands/next?wait_s=0", headers=service.robot, timeout=10
    )
    assert answer.status_code == 204


def test_the_same_idempotency_key_returns_the_same_command(service: Service) -> None:
    body = {"type": "say", "args": {"text": "once"}, "idempotency_key": "k-1"}
    first = requests.post(
        f"{service.url}/robots/hbs2/commands", json=body, headers=service.operator, timeout=10
    )
    second = requests.post(
        f"{service.url}/robots/hbs2/commands", json=body, headers=service.operator, timeout=10
    )
    assert (first.status_code, second.status_code) == (201, 200)
    assert first.json()["id"] == second.json()["id"]


def test_what_a_caller_may_not_see_answers_404_and_no_token_401(service: Service) -> None:
    sent = requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {}},
        headers=service.operator,
        timeout=10,
    ).json()
    assert requests.get(f"{service.url}/robots", timeout=10).status_code == 401
    assert (
        requests.get(f"{service.url}/robots", headers=bearer("nope"), timeout=10).status_code == 401
    )
    assert requests.get(f"{service.url}/robots", headers=service.stranger, timeout=10).json() == []
    assert (
        requests.get(
            f"{service.url}/robots/hbs2/commands", headers=service.stranger, timeout=10
        ).status_code
        == 404
    )
    assert (
        requests.get(
            f"{service.url}/robots/nosuch/telemetry", headers=service.operator, timeout=10
        ).status_code
        == 404
    )
    # another robot never sees it, nor can it report on it
    assert (
        requests.get(
            f"{service.url}/robot/commands/next", headers=service.other_robot, timeout=10
        ).status_code
        == 204
    )
    foreign = requests.post(
        f"{service.url}/robot/commands/{sent['id']}/result",
        json={"status": "SUCCEEDED"},
        headers=service.other_robot,
        timeout=10,
    )
    assert foreign.status_code == 404
    # a robot's token is not an operator's
    assert (
        requests.get(f"{service.url}/robots", headers=service.robot, timeout=10).status_code == 404
    )


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"args": {}}, "type"),
        ({"type": "say", "args": []}, "args"),
        ({"type": "Say!", "args": {}}, "type"),
        ({"type": "say", "timeout_s": -1}, "timeout_s"),
        ({"type": "say", "colour": "red"}, "colour"),
    ],
)
def test_a_bad_body_is_422_naming_the_field(service: Service, body: dict, field: str) -> None:
    answer = requests.post(
        f"{service.url}/robots/hbs2/commands", json=body, headers=service.operator, timeout=10
    )
    assert answer.status_code == 422
    assert field in [problem["field"] for problem in answer.json()["detail"]]


def test_a_body_over_the_limit_is_413_and_broken_json_422(service: Service) -> None:
    huge = {"type": "say", "args": {"text": "x" * 100_000}}
    answer = requests.post(
        f"{service.url}/robots/hbs2/commands", json=huge, headers=service.operator, timeout=10
    )
    assert answer.status_code == 413
    broken = requests.post(
        f"{service.url}/robots/hbs2/commands",
        data=b"{not json",
        headers={**service.operator, "Content-Type": "application/json"},
        timeout=10,
    )
    assert broken.status_code == 422


def test_telemetry_pushed_by_the_robot_is_seen_by_its_operator(service: Service) -> None:
    pushed = requests.post(
        f"{service.url}/robot/telemetry",
        json={"values": {"/sensors/temperature/c": 22.1}},
        headers=service.robot,
        timeout=10,
    )
    assert pushed.status_code == 204
    latest = requests.get(
        f"{service.url}/robots/hbs2/telemetry", headers=service.operator, timeout=10
    ).json()
    assert latest["/sensors/temperature/c"]["value"] == 22.1
    robots = requests.get(f"{service.url}/robots", headers=service.operator, timeout=10).json()
    assert robots[0]["online"] is True and robots[1]["online"] is False
