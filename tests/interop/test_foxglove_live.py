"""A lab watches a running session in Foxglove: `vest run --foxglove` serves it through
Foxglove's own SDK on loopback, with the topics of the MCAP export; read here by a client
that speaks Foxglove's WebSocket protocol as the app does."""

from __future__ import annotations

import json
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from websockets.sync.client import connect

from engine.clock import VirtualClock
from engine.errors import ConfigError
from engine.interop.foxglove_live import FoxgloveLive

ROOT = Path(__file__).resolve().parents[2]
VEST = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
PROTOCOL = "foxglove.sdk.v1"


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
        assert url.startswith("ws://127.0.0.1:")
        channels: dict[str, int] = {}
        subscribed = False
        names: dict[str, str] = {}
        with connect(url, subprotocols=[PROTOCOL], open_timeout=10) as client:
            first = json.loads(client.recv(timeout=10))
            assert first["op"] == "serverInfo" and first["name"] == "vest"
            while True:  # channels are advertised as their topics first carry something
                frame = client.recv(timeout=20)
                if isinstance(frame, bytes):
                    break
                message = json.loads(frame)
                if message["op"] != "advertise":
                    continue
                for channel in message["channels"]:
                    channels[channel["topic"]] = channel["id"]
                    names[channel["topic"]] = channel["schemaName"]
                    assert (
                        channel["encoding"] == "json" and channel["schemaEncoding"] == "jsonschema"
                    )
                if "/vest/actions" in channels and not subscribed:
                    subscription = {"id": 1, "channelId": channels["/vest/actions"]}
                    client.send(json.dumps({"op": "subscribe", "subscriptions": [subscription]}))
                    subscribed = True
            opcode, subscription_id, _ = struct.unpack_from("<BIQ", frame)
            action = json.loads(frame[13:])
        assert (opcode, subscription_id) == (1, 1)
        assert {"tree", "action", "args"} <= set(action)
        assert "/vest/trees/hug/status" in channels and "/vest/blackboard" in channels
        assert names["/vest/actions"] == "vest.Action"  # as the MCAP export names it
    finally:
        robot.wait(timeout=60)
    assert robot.returncode == 0


def test_foxglove_is_served_on_this_machine_only() -> None:
    with pytest.raises(ConfigError, match="Foxglove's server has no token"):
        FoxgloveLive("0.0.0.0", 8765, VirtualClock(), 0.0)
