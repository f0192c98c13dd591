"""A lab watches a running session in Foxglove: `vest run --foxglove` serves it on loopback
with the topics of the MCAP export, read here as the app reads it (Foxglove's own client,
and a plain WebSocket client speaking its protocol). Like every page of vest, it asks for
its token and refuses another site's page."""

from __future__ import annotations

import json
import re
import shutil
import struct
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import ClientConnection, connect

from engine.clock import VirtualClock
from engine.errors import ConfigError
from engine.interop.foxglove_live import FoxgloveLive
from engine.session.events import ActionStarted

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[2]
CLIENT = Path(__file__).resolve().parent / "foxglove_client"
VEST = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
PROTOCOL = "foxglove.sdk.v1"
SAID = ActionStarted(1.0, 1, "hug", "say", {"text": "I love hugs!"})


@pytest.fixture
def live() -> Iterator[FoxgloveLive]:
    server = FoxgloveLive("127.0.0.1", 0, VirtualClock(), 1.7e9)
    server.start()
    yield server
    server.stop()


def first_message(client: ClientConnection, topic: str) -> tuple[dict[str, object], bytes]:
    """(the server's info, the first message of ``topic``), subscribing as it is advertised."""
    info = json.loads(client.recv(timeout=10))
    while True:
        frame = client.recv(timeout=20)
        if isinstance(frame, bytes):
            return info, frame
        message = json.loads(frame)
        for channel in message.get("channels", []):
            if channel["topic"] == topic:
                subscription = {"id": 7, "channelId": channel["id"]}
                client.send(json.dumps({"op": "subscribe", "subscriptions": [subscription]}))


def test_the_robot_s_actions_reach_a_foxglove_client_as_they_happen() -> None:
    robot = subprocess.Popen(
        [*VEST, "run", "--speech", "text", "--duration", "6", "--foxglove", "0"],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert robot.stderr is not None
        url = next(
            m.group(1) for line in robot.stderr if (m := re.search(r"foxglove: (\S+)", line))
        )
        assert re.fullmatch(r"ws://127\.0\.0\.1:\d+/\?token=[\w-]{32}", url)
        with connect(url, subprotocols=[PROTOCOL], open_timeout=10) as client:
            info, frame = first_message(client, "/vest/actions")
        opcode, subscription_id, _ = struct.unpack_from("<BIQ", frame)
        action = json.loads(frame[13:])
        assert info["op"] == "serverInfo" and info["name"] == "vest"
        assert (opcode, subscription_id) == (1, 7)
        assert {"tree", "action", "args"} <= set(action)
    finally:
        robot.wait(timeout=60)
    assert robot.returncode == 0


def test_foxglove_s_own_client_reads_the_session(live: FoxgloveLive) -> None:
    node = shutil.which("node")
    assert node is not None, "Node.js is needed for Foxglove's client (scripts/setup)"
    assert (CLIENT / "node_modules/@foxglove/ws-protocol").is_dir(), "run scripts/setup"
    reader = subprocess.Popen(
        [node, "read_topic.mjs", live.url, "/vest/actions"],
        cwd=CLIENT,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert reader.stdout is not None
    for _ in range(200):  # told again and again until the client has subscribed and read one
        live.on_event(SAID)
        try:
            output, _ = reader.communicate(timeout=0.1)
            break
        except subprocess.TimeoutExpired:
            continue
    else:
        reader.kill()
        output, _ = reader.communicate()
    seen = json.loads(output)
    assert reader.returncode == 0, seen
    assert seen["server"] == "vest" and "/vest/actions" in seen["topics"]
    assert seen["message"]["args"] == {"text": "I love hugs!"} and seen["message"]["tree"] == "hug"


def test_a_connection_without_the_token_is_refused(live: FoxgloveLive) -> None:
    without = live.url.split("?")[0]
    with pytest.raises(InvalidStatus) as refused:
        connect(without, subprotocols=[PROTOCOL], open_timeout=10)
    assert refused.value.response.status_code == 403
    wrong = without + "?token=" + "x" * 32
    with pytest.raises(InvalidStatus):
        connect(wrong, subprotocols=[PROTOCOL], open_timeout=10)


def test_another_site_s_page_is_refused_even_with_the_token(live: FoxgloveLive) -> None:
    evil = {"Origin": "https://evil.example"}
    with pytest.raises(InvalidStatus) as refused:
        connect(live.url, subprotocols=[PROTOCOL], additional_headers=evil, open_timeout=10)
    assert refused.value.response.status_code == 403


def test_a_site_named_with_foxglove_origin_may_connect_with_the_token() -> None:
    app = "https://app.foxglove.dev"
    live = FoxgloveLive("127.0.0.1", 0, VirtualClock(), 1.7e9, origins=[app])
    live.start()
    try:
        headers = {"Origin": app}
        with connect(live.url, subprotocols=[PROTOCOL], additional_headers=headers) as client:
            assert json.loads(client.recv(timeout=10))["op"] == "serverInfo"
        with pytest.raises(InvalidStatus):
            connect(live.url.split("?")[0], subprotocols=[PROTOCOL], additional_headers=headers)
    finally:
        live.stop()


def test_a_client_s_nonsense_is_answered_never_raised(live: FoxgloveLive) -> None:
    with connect(live.url, subprotocols=[PROTOCOL], open_timeout=10) as client:
        client.recv(timeout=10)  # its info
        client.send("not json")
        client.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": "a"}, 3]}))
        client.send(json.dumps({"op": "advertise", "channels": []}))
        told = [json.loads(client.recv(timeout=10)) for _ in range(2)]
        live.on_event(SAID)  # still served: a new channel is advertised
        advertised = json.loads(client.recv(timeout=10))
    assert [message["op"] for message in told] == ["status", "status"]
    assert "does not take 'advertise'" in told[1]["message"]
    assert advertised["op"] == "advertise"


def test_foxglove_is_served_on_this_machine_only() -> None:
    with pytest.raises(ConfigError, match="on this machine only"):
        FoxgloveLive("0.0.0.0", 8765, VirtualClock(), 0.0)


def test_an_origin_option_that_is_no_origin_is_named() -> None:
    said = subprocess.run(
        [*VEST, "run", "--foxglove", "0", "--foxglove-origin", "app.foxglove.dev/x"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert said.returncode == 2 and "an origin is scheme://host[:port]" in said.stderr


def test_a_refusal_says_why(live: FoxgloveLive) -> None:
    """A lab can tell a missing token from an old one, another site's page and a client
    that does not speak the protocol."""
    base = live.url.split("?")[0]
    evil = {"Origin": "https://evil.example"}
    for url, headers, protocols, said in [
        (base, {}, [PROTOCOL], "a token is needed"),
        (base + "?token=" + "x" * 32, {}, [PROTOCOL], "not this server's"),
        (live.url, evil, [PROTOCOL], "https://evil.example"),
        (live.url, {}, ["chat"], "foxglove.websocket.v1"),
    ]:
        with pytest.raises(InvalidStatus) as refused:
            connect(url, subprotocols=protocols, additional_headers=headers, open_timeout=10)
        assert said in refused.value.response.body.decode(), said
