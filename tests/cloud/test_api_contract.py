"""The /api/v1 contract, end to end against a real uvicorn server on loopback."""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import requests
from sqlalchemy.exc import OperationalError

from cloud.services import CloudStore
from cloud.settings import Settings
from engine.clock import VirtualClock


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


@pytest.fixture
def service(db_url: str, start_service: Callable[..., Any]) -> Service:
    running = start_service(Settings(db_url=db_url, max_wait_s=10.0, recheck_s=0.5))
    directory = running.store.directory
    ana = directory.add_operator("ana")
    robot = directory.add_robot("hbs2", operator="ana")
    other = directory.add_robot("hbs3", operator="ana")
    stranger = directory.add_operator("zed")
    return Service(
        running.api, running.store, bearer(ana), bearer(robot), bearer(other), bearer(stranger)
    )


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
    assert claimed.json()["lease_s"] == service.store.ledger.lease_s
    still_at_it = requests.post(
        f"{service.url}/robot/commands/{command['id']}/progress", headers=service.robot, timeout=10
    )
    assert still_at_it.status_code == 200 and still_at_it.json()["state"] == "IN_PROGRESS"
    not_its_own = requests.post(
        f"{service.url}/robot/commands/{command['id']}/progress",
        headers=service.other_robot,
        timeout=10,
    )
    assert not_its_own.status_code == 404
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
    other = {"type": "led", "args": {"color": "blue"}, "idempotency_key": "k-1"}
    reused = requests.post(
        f"{service.url}/robots/hbs2/commands", json=other, headers=service.operator, timeout=10
    )
    assert reused.status_code == 409 and "use a new key" in reused.json()["detail"]


def test_what_a_caller_may_not_see_answers_404_and_no_token_401(service: Service) -> None:
    sent = requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hi"}},
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
        ({"type": "say", "args": {"text": "hi"}, "timeout_s": True}, "timeout_s"),  # not 1 s
        ({"type": "say", "args": {"text": "hi"}, "timeout_s": "5"}, "timeout_s"),
        ({"type": "say", "colour": "red"}, "colour"),
        # arguments of built-in types, checked as the robot checks them
        ({"type": "say", "args": {"text": "hi", "volume": 5}}, "args"),
        ({"type": "say", "args": {}}, "args"),
        ({"type": "move", "args": {"joint": "neck", "angle_deg": 500}}, "args"),
        ({"type": "led", "args": {"color": "#zz"}}, "args"),
        ({"type": "read", "args": {"sensor": "smell"}}, "args"),
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
    assert broken.json()["detail"][0]["field"] == "body"  # not the character offset


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


def post_raw(service: Service, path: str, raw: bytes | Any, who: dict[str, str]) -> Any:
    return requests.post(
        f"{service.url}{path}",
        data=raw,
        headers={**who, "Content-Type": "application/json"},
        timeout=10,
    )


@pytest.mark.parametrize(
    ("path", "raw", "field"),
    [
        ("/robots/hbs2/commands", b'{"type": "move", "args": {"angle_deg": NaN}}', "args"),
        ("/robot/telemetry", b'{"values": {"/sensors/x": Infinity}}', "values"),
        ("/robot/telemetry", b'{"values": {"": 1}}', "values"),
        ("/robot/telemetry", b'{"values": {"' + b"k" * 201 + b'": 1}}', "values"),
        ("/robot/commands/nope/result", b'{"status": "SUCCEEDED", "result": -Infinity}', "result"),
        ("/robot/commands/nope/result", b'{"status": "DONE"}', "status"),
        # a lone surrogate parses, but can be neither stored in PostgreSQL nor sent back
        ("/robot/commands/nope/result", b'{"status": "FAILED", "result": "\\ud800"}', "result"),
        ("/robots/hbs2/commands", b'{"type": "say", "args": {"\\udfff": 1}}', "args"),
        ("/robots/hbs2/commands", b'{"type": "say", "idempotency_key": "\\ud800"}', "idem"),
        ("/robot/telemetry", b'{"values": {"/s/\\ud800": 1}}', "values"),
        # a NUL parses, and no PostgreSQL text or JSON can hold it: anywhere it is stored
        ("/robots/hbs2/commands", b'{"type": "say", "idempotency_key": "k\\u0000"}', "idem"),
        ("/robots/hbs2/commands", b'{"type": "say", "args": {"text": "a\\u0000b"}}', "args"),
        ("/robots/hbs2/commands", b'{"type": "say", "args": {"t\\u0000": 1}}', "args"),
        ("/robot/commands/nope/result", b'{"status": "FAILED", "result": "\\u0000"}', "result"),
        ("/robot/telemetry", b'{"values": {"/s/\\u0000": 1}}', "values"),
        ("/robot/telemetry", b'{"values": {"/s": "\\u0000"}}', "values"),
        # JSON no parser here reads: nested past Python's recursion, a 5,000-digit number
        (
            "/robots/hbs2/commands",
            b'{"type": "say", "args": {"a": ' + b"[" * 5000 + b"]" * 5000 + b"}}",
            "body",
        ),
        ("/robot/telemetry", b'{"values": {"/x": 1' + b"0" * 5000 + b"}}", "body"),
    ],
)
def test_what_json_cannot_carry_and_odd_keys_are_422(
    service: Service, path: str, raw: bytes, field: str
) -> None:
    who = service.operator if path.startswith("/robots/") else service.robot
    answer = post_raw(service, path, raw, who)
    assert answer.status_code == 422
    assert any(problem["field"].startswith(field) for problem in answer.json()["detail"])


def test_a_streamed_body_over_the_limit_is_413_too(service: Service) -> None:
    def chunks() -> Any:  # no Content-Length: the body arrives chunked
        yield b'{"type": "say", "args": {"text": "'
        for _ in range(100):
            yield b"x" * 1024
        yield b'"}}'

    answer = post_raw(service, "/robots/hbs2/commands", chunks(), service.operator)
    assert answer.status_code == 413
    listed = requests.get(
        f"{service.url}/robots/hbs2/commands", headers=service.operator, timeout=10
    )
    assert listed.json() == []


def test_the_command_types_are_those_the_robot_checks(service: Service) -> None:
    types = requests.get(
        f"{service.url}/robots/hbs2/command-types", headers=service.operator, timeout=10
    ).json()
    assert set(types) == {"say", "led", "move", "read"}
    move = {arg["name"]: arg for arg in types["move"]}
    assert move["angle_deg"]["required"] and move["angle_deg"]["schema"]["maximum"] == 180.0
    hidden = requests.get(
        f"{service.url}/robots/hbs2/command-types", headers=service.stranger, timeout=10
    )
    assert hidden.status_code == 404


def server_sent_events(lines: Any) -> Iterator[tuple[str, Any]]:
    """(event name, data) for each server-sent event in a streamed response's lines."""
    name = "message"
    for line in lines:
        if line.startswith("event:"):
            name = line.removeprefix("event:").strip()
        elif line.startswith("data:"):
            yield name, json.loads(line.removeprefix("data:"))


def test_the_live_stream_shows_robots_and_every_change_of_a_command(service: Service) -> None:
    sent = requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hello"}},
        headers=service.operator,
        timeout=10,
    ).json()
    with requests.get(
        f"{service.url}/events", headers=service.operator, stream=True, timeout=10
    ) as stream:
        assert stream.headers["content-type"].startswith("text/event-stream")
        events = server_sent_events(stream.iter_lines(chunk_size=1, decode_unicode=True))
        name, robots = next(events)
        assert name == "robots" and [robot["name"] for robot in robots] == ["hbs2", "hbs3"]
        assert next(events) == ("command", {**sent, "robot": "hbs2"})
        requests.get(f"{service.url}/robot/commands/next", headers=service.robot, timeout=10)
        states = []
        for name, data in events:  # a read timeout fails the test if the change never comes
            if name == "command" and data["id"] == sent["id"]:
                states.append(data["state"])
                break
        assert states == ["IN_PROGRESS"]


def test_the_live_stream_needs_an_operator_token(service: Service) -> None:
    assert requests.get(f"{service.url}/events", timeout=10).status_code == 401
    assert (
        requests.get(f"{service.url}/events", headers=service.robot, timeout=10).status_code == 404
    )


def test_the_page_is_served_with_a_strict_content_policy(service: Service) -> None:
    home = requests.get(service.url.removesuffix("/api/v1") + "/", timeout=10)
    assert home.status_code == 200 and "<title>vest: robots</title>" in home.text
    assert "default-src 'self'" in home.headers["content-security-policy"]
    script = requests.get(service.url.removesuffix("/api/v1") + "/operator/app.js", timeout=10)
    assert script.status_code == 200 and "javascript" in script.headers["content-type"]


def test_a_long_poll_replaced_by_a_newer_one_of_the_same_robot_takes_nothing(
    tmp_path: Path, start_service: Callable[..., Any]
) -> None:
    clock = VirtualClock(start_s=1000.0)  # long-polls wait until woken: nothing times out
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"), clock)
    operator = bearer(running.store.directory.add_operator("ana"))
    robot = bearer(running.store.directory.add_robot("hbs2", operator="ana"))
    answers: dict[str, requests.Response] = {}

    def poll(name: str) -> None:
        answers[name] = requests.get(
            f"{running.api}/robot/commands/next?wait_s=30", headers=robot, timeout=30
        )

    stale = threading.Thread(target=poll, args=("stale",))
    stale.start()
    # the service's telemetry writer waits on the clock too: two waiters = the poll waits
    assert clock.until_waiting(2)  # the first long-poll waits (its robot lost the reply)
    fresh = threading.Thread(target=poll, args=("fresh",))
    fresh.start()
    stale.join(timeout=30)
    assert answers["stale"].status_code == 204  # replaced: it ends, taking nothing
    assert clock.until_waiting(2)
    sent = requests.post(
        f"{running.api}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hi"}},
        headers=operator,
        timeout=10,
    ).json()
    fresh.join(timeout=30)
    assert answers["fresh"].status_code == 200 and answers["fresh"].json()["id"] == sent["id"]


@pytest.mark.parametrize(
    ("method", "path", "who"),
    [
        ("GET", "/robots/hbs2%00/commands", "operator"),
        ("GET", "/robots/hbs2/commands/abc%00def", "operator"),
        ("POST", "/robots/hbs2/commands/abc%00def/cancel", "operator"),
        ("POST", "/robot/commands/abc%00def/progress", "robot"),
        ("GET", "/robots/%E2%82%AC%00/telemetry", "operator"),
    ],
)
def test_a_nul_in_a_name_or_an_id_names_nothing(
    service: Service, method: str, path: str, who: str
) -> None:
    headers = service.operator if who == "operator" else service.robot
    answer = requests.request(method, service.url + path, headers=headers, timeout=10)
    assert answer.status_code == 404, answer.text


def test_a_database_that_cannot_store_answers_503_in_json_and_keeps_what_it_had(
    service: Service, monkeypatch: pytest.MonkeyPatch
) -> None:
    kept = requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "before"}},
        headers=service.operator,
        timeout=10,
    )
    assert kept.status_code == 201

    def disk_full(*args: Any, **kwargs: Any) -> Any:
        raise OperationalError("INSERT INTO commands", {}, Exception("database or disk is full"))

    monkeypatch.setattr(service.store.ledger, "submit", disk_full)  # as a full disk answers
    answer = requests.post(
        f"{service.url}/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "after"}},
        headers=service.operator,
        timeout=10,
    )
    assert answer.status_code == 503
    assert "database or disk is full" in answer.json()["detail"]
    monkeypatch.undo()
    listed = requests.get(f"{service.url}/robots/hbs2/commands", headers=service.operator)
    assert [c["args"]["text"] for c in listed.json()] == ["before"]


def test_the_openapi_document_describes_the_errors_the_service_sends(service: Service) -> None:
    spec = requests.get(service.url.removesuffix("/api/v1") + "/openapi.json", timeout=10).json()
    send = spec["paths"]["/api/v1/robots/{robot}/commands"]["post"]["responses"]
    assert {"401", "404", "409", "413", "422", "503"} <= set(send)
    problems = send["422"]["content"]["application/json"]["schema"]["$ref"].split("/")[-1]
    fields = spec["components"]["schemas"][problems]["properties"]["detail"]["items"]
    assert fields["$ref"].endswith("/Problem")
    sent = requests.post(
        f"{service.url}/robots/hbs2/commands", json={"args": {}}, headers=service.operator
    )
    assert set(sent.json()["detail"][0]) == {"field", "message"}  # what the document says


def test_a_robot_s_telemetry_is_bounded_however_often_it_pushes(service: Service) -> None:
    push = f"{service.url}/robot/telemetry"
    first = {f"/sensors/k{i}": i for i in range(500)}
    assert requests.post(push, json={"values": first}, headers=service.robot).status_code == 204
    again = {key: value + 1 for key, value in first.items()}  # updating them is fine
    assert requests.post(push, json={"values": again}, headers=service.robot).status_code == 204
    more = requests.post(push, json={"values": {"/sensors/new": 1}}, headers=service.robot)
    assert more.status_code == 422
    assert "may hold 500" in more.json()["detail"][0]["message"]
    big = requests.post(push, json={"values": {"/sensors/k1": "x" * 2000}}, headers=service.robot)
    assert big.status_code == 422 and "at most 1024" in big.text
    huge = 10**4000  # one number, 4 KB of JSON
    for value in (huge, [10**1000] * 32, -(2**63) - 1):
        body = json.dumps({"values": {"/sensors/k1": value}})
        as_json = {**service.robot, "Content-Type": "application/json"}
        answer = requests.post(push, data=body, headers=as_json)
        assert answer.status_code == 422
        assert "within 64 bits" in answer.text or "at most 1024" in answer.text
    edge = {"/sensors/k1": 2**63 - 1, "/sensors/k2": [-(2**63)] * 32}
    assert requests.post(push, json={"values": edge}, headers=service.robot).status_code == 204
    seen = requests.get(f"{service.url}/robots/hbs2/telemetry", headers=service.operator)
    assert len(seen.json()) == 500 and seen.json()["/sensors/k7"]["value"] == 8
    assert seen.json()["/sensors/k1"]["value"] == 2**63 - 1
