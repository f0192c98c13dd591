"""Each person's account has a role, and every endpoint keeps to it: an admin sees and
commands every robot, an operator the robots granted to it, a therapist watches them
(commands and telemetry) without commanding, a viewer sees their state and commands but
never telemetry (a child's data). Against a real server on loopback."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pytest
import requests

from cloud.services import CloudStore
from cloud.settings import Settings
from engine.clock import VirtualClock
from tests.cloud.test_api_contract import bearer, server_sent_events


@dataclass
class Team:
    api: str
    store: CloudStore
    clock: VirtualClock
    tokens: dict[str, dict[str, str]]

    def get(self, who: str, path: str) -> requests.Response:
        return requests.get(f"{self.api}{path}", headers=self.tokens[who], timeout=10)

    def post(self, who: str, path: str, body: Any = None) -> requests.Response:
        return requests.post(f"{self.api}{path}", json=body, headers=self.tokens[who], timeout=10)


@pytest.fixture
def team(db_url: str, start_service: Callable[..., Any]) -> Team:
    """hbs2 is granted to ana (operator), tess (therapist) and vic (viewer); hbs3 to no one
    but its owner ben; ada is an admin granted nothing."""
    clock = VirtualClock(start_s=1_800_000_000.0)
    running = start_service(Settings(db_url=db_url, token_cache_s=5.0), clock)
    directory = running.store.directory
    tokens = {
        "ana": directory.add_operator("ana"),
        "ben": directory.add_operator("ben"),
        "tess": directory.add_operator("tess", role="therapist"),
        "vic": directory.add_operator("vic", role="viewer"),
        "ada": directory.add_operator("ada", role="admin"),
        "hbs2": directory.add_robot("hbs2", operator="ana"),
    }
    directory.add_robot("hbs3", operator="ben")
    for person in ("tess", "vic"):
        directory.grant(person, "hbs2")
    return Team(running.api, running.store, clock, {k: bearer(v) for k, v in tokens.items()})


SAY = {"type": "say", "args": {"text": "hello"}}


def test_an_admin_sees_and_commands_every_robot_granted_or_not(team: Team) -> None:
    assert [r["name"] for r in team.get("ada", "/robots").json()] == ["hbs2", "hbs3"]
    assert team.post("ada", "/robots/hbs3/commands", SAY).status_code == 201
    assert team.get("ada", "/robots/hbs3/telemetry").status_code == 200


def test_an_operator_sees_only_the_robots_granted_to_it(team: Team) -> None:
    assert [r["name"] for r in team.get("ana", "/robots").json()] == ["hbs2"]
    assert team.post("ana", "/robots/hbs2/commands", SAY).status_code == 201
    assert team.post("ana", "/robots/hbs3/commands", SAY).status_code == 404


def test_a_therapist_watches_commands_and_telemetry_but_sends_and_cancels_nothing(
    team: Team,
) -> None:
    team.post("hbs2", "/robot/telemetry", {"values": {"/sensors/force/left_n": 3.5}})
    sent = team.post("ana", "/robots/hbs2/commands", SAY).json()
    assert (
        team.get("tess", "/robots/hbs2/telemetry").json()["/sensors/force/left_n"]["value"] == 3.5
    )
    assert [c["id"] for c in team.get("tess", "/robots/hbs2/commands").json()] == [sent["id"]]
    refused = team.post("tess", "/robots/hbs2/commands", SAY)
    assert refused.status_code == 403
    assert refused.json()["detail"].startswith(
        "tess has the role 'therapist', which may not send or cancel commands; "
        "only admin, operator may"
    )
    assert team.post("tess", f"/robots/hbs2/commands/{sent['id']}/cancel").status_code == 403
    assert team.get("ana", f"/robots/hbs2/commands/{sent['id']}").json()["state"] == "QUEUED"


def test_a_viewer_sees_the_robot_and_its_commands_but_never_telemetry(team: Team) -> None:
    team.post("hbs2", "/robot/telemetry", {"values": {"/sensors/force/left_n": 3.5}})
    sent = team.post("ana", "/robots/hbs2/commands", SAY).json()
    assert [r["name"] for r in team.get("vic", "/robots").json()] == ["hbs2"]
    assert team.get("vic", f"/robots/hbs2/commands/{sent['id']}").status_code == 200
    refused = team.get("vic", "/robots/hbs2/telemetry")
    assert refused.status_code == 403
    assert "'viewer', which may not see telemetry" in refused.json()["detail"]
    assert "vest cloud set-role NAME ROLE" in refused.json()["detail"]
    assert team.post("vic", "/robots/hbs2/commands", SAY).status_code == 403
    # a robot the viewer may not see is refused for its role first: nothing is revealed
    assert team.get("vic", "/robots/hbs3/telemetry").status_code == 403


def test_a_viewer_s_live_stream_carries_commands_and_no_telemetry(team: Team) -> None:
    team.post("hbs2", "/robot/telemetry", {"values": {"/sensors/force/left_n": 3.5}})
    team.post("ana", "/robots/hbs2/commands", SAY)

    def stream_of(who: str) -> list[str]:
        """The events a person's stream starts with, up to a command sent once it is open
        (everything there already comes in the first batch, before that command)."""
        known = {c["id"] for c in team.get("ana", "/robots/hbs2/commands").json()}
        with requests.get(
            f"{team.api}/events", headers=team.tokens[who], stream=True, timeout=10
        ) as stream:
            names = []
            for name, data in server_sent_events(
                stream.iter_lines(chunk_size=1, decode_unicode=True)
            ):
                names.append(name)
                if name == "command" and data["id"] not in known:
                    return names
                if name == "command" and len(names) == 1 + len(known):  # all there were
                    team.post("ana", "/robots/hbs2/commands", SAY)
        raise AssertionError(f"the stream ended after {names}")

    assert stream_of("vic") == ["robots", "command", "command"]
    assert stream_of("tess") == ["robots", *["command"] * 2, "telemetry", "command"]


def test_each_person_learns_their_role_and_what_it_allows(team: Team) -> None:
    assert team.get("vic", "/me").json() == {
        "name": "vic",
        "role": "viewer",
        "can_command": False,
        "can_press": False,
        "sees_telemetry": False,
        "expires_at_s": 1_800_000_000.0 + 90 * 86_400,
    }
    assert team.get("ada", "/me").json()["can_command"] is True
    assert team.get("tess", "/me").json()["can_press"] is True  # a therapist presses buttons
    assert team.get("hbs2", "/me").status_code == 404  # robots have no account


def test_a_role_changed_by_the_admin_holds_within_the_token_cache_time(team: Team) -> None:
    assert team.post("vic", "/robots/hbs2/commands", SAY).status_code == 403
    team.store.directory.set_role("vic", "operator")  # as `vest cloud set-role` does
    team.clock.advance(5.1)
    assert team.post("vic", "/robots/hbs2/commands", SAY).status_code == 201
    team.store.directory.set_role("vic", "viewer")
    team.clock.advance(5.1)
    assert team.get("vic", "/robots/hbs2/telemetry").status_code == 403


def test_a_viewer_sees_a_command_but_not_the_sensor_values_it_brought_back(team: Team) -> None:
    sent = team.post("ana", "/robots/hbs2/commands", {"type": "read", "args": {"sensor": "force"}})
    command = sent.json()["id"]
    assert team.get("hbs2", "/robot/commands/next?wait_s=0").status_code == 200
    values = {"/sensors/force/left_n": 4.0}
    result = {"status": "SUCCEEDED", "result": values}
    assert team.post("hbs2", f"/robot/commands/{command}/result", result).status_code == 200
    as_therapist = team.get("tess", f"/robots/hbs2/commands/{command}").json()
    assert as_therapist["result"] == values and not as_therapist["result_hidden"]
    for shown in (
        team.get("vic", f"/robots/hbs2/commands/{command}").json(),
        team.get("vic", "/robots/hbs2/commands").json()[0],
    ):
        assert shown["state"] == "SUCCEEDED" and shown["result"] is None
        assert shown["result_hidden"]
