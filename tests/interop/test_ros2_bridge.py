"""A lab's ROS 2 graph sees the robot: `vest run --ros2` joins it as rmw_zenoh nodes do.

The lab here is a Zenoh peer in the test process, listening as rmw_zenoh's router would,
that reads what a ROS 2 node reads (the liveliness tokens of the graph, CDR messages on
rmw_zenoh's key expressions, decoded with rosbags' ROS 2 types) and sends a command as
`ros2 topic pub /vest/command std_msgs/msg/String` would.
"""

from __future__ import annotations

import json
import os
import re
import socket
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.realtime

zenoh = pytest.importorskip("zenoh")  # the ros2 extra

from engine.blackboard.board import Blackboard  # noqa: E402
from engine.blackboard.catalogue import (  # noqa: E402
    FORCE_LEFT_N,
    IOT_INBOX,
    TOUCH_ANY,
    default_catalogue,
)
from engine.clock import VirtualClock  # noqa: E402
from engine.interop.ros2_bridge import Ros2Bridge  # noqa: E402
from engine.interop.ros2_plan import Ros2Plan  # noqa: E402
from engine.interop.ros2_wire import Wire, attachment, session_config  # noqa: E402
from engine.privacy.consent import Consent  # noqa: E402
from engine.privacy.consent_gate import ConsentGates  # noqa: E402
from engine.session.events import (  # noqa: E402
    ActionStarted,
    KeyChanged,
    NodeInfo,
    NodeStatus,
    SessionEvent,
    TreeStarted,
)
from engine.session.stream import SessionStream  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
VEST = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
"""std_msgs/msg/String's type hash as ROS 2 Jazzy computes it (`ros2 topic info -v`)."""
WAIT_S = 30.0
WIRE = Wire()


class Lab:
    """A Zenoh peer that reads the graph as a ROS 2 node would."""

    def __init__(self) -> None:
        probe = socket.socket()
        probe.bind(("127.0.0.1", 0))
        self.endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
        probe.close()
        self.session = zenoh.open(session_config(None, None, listen=self.endpoint))
        self.samples: list[tuple[str, bytes, bytes | None]] = []
        self.tokens: list[str] = []
        self.arrived = threading.Condition()
        self.prefix = ""  # the robot's namespace, as its topics begin ('' or /sim)
        self._subscriber = self.session.declare_subscriber("0/**", self._sample)
        self._tokens = self.session.liveliness().declare_subscriber(
            "@ros2_lv/**", self._token, history=True
        )

    def _sample(self, sample: Any) -> None:
        extra = sample.attachment.to_bytes() if sample.attachment is not None else None
        with self.arrived:
            self.samples.append((str(sample.key_expr), sample.payload.to_bytes(), extra))
            self.arrived.notify_all()

    def _token(self, sample: Any) -> None:
        with self.arrived:
            if sample.kind == zenoh.SampleKind.PUT:
                self.tokens.append(str(sample.key_expr))
            self.arrived.notify_all()

    def messages(self, topic: str, typename: str) -> list[Any]:
        """What has come on ``topic`` (as ROS 2 names it), decoded as ``typename``."""
        prefix = f"0/{topic.lstrip('/')}/"
        with self.arrived:
            found = [payload for key, payload, _ in self.samples if key.startswith(prefix)]
        return [WIRE.decode(typename, payload) for payload in found]

    def wait_for(self, what: str, found: Any) -> Any:
        """Waits (at most WAIT_S) until ``found()`` gives something, and returns it."""
        with self.arrived:
            result = self.arrived.wait_for(found, timeout=WAIT_S)
        assert result, f"the lab never saw {what}"
        return result

    def listening_for_commands(self) -> None:
        """Waits until the robot's command subscription is on the graph."""
        self.wait_for("the command subscription", lambda: [t for t in self.tokens if "/MS/" in t])

    def two_results(self, what: str) -> list[dict[str, Any]]:
        """Waits for a command's second result (after RECEIVED), and returns them all."""
        return self.wait_for(what, lambda: len(self.results()) > 1 and self.results())

    def results(self) -> list[dict[str, Any]]:
        topic = f"{self.prefix}/vest/command/result"
        return [json.loads(m.data) for m in self.messages(topic, STRING)]

    def send(self, text: str) -> None:
        """A command, as `ros2 topic pub /vest/command std_msgs/msg/String` sends it."""
        key = f"0{self.prefix}/vest/command/std_msgs::msg::dds_::String_/{STRING_HASH}"
        payload = WIRE.encode(STRING, {"data": text})
        self.session.put(key, payload, attachment=attachment(1, 0, bytes(16)))

    def close(self) -> None:
        self.session.close()


STRING = "std_msgs/msg/String"


@pytest.fixture
def lab() -> Iterator[Lab]:
    graph = Lab()
    yield graph
    graph.close()


class GatedBridge:
    """The bridge behind the consent gate, as a session builds it: an event told here
    is published on the robot's stream and reaches the bridge through the gate."""

    def __init__(self, bridge: Ros2Bridge, stream: SessionStream) -> None:
        self.bridge, self.stream = bridge, stream

    def on_event(self, event: SessionEvent) -> None:
        self.stream.publish(event)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.bridge, name)


def bridge_on(
    lab: Lab, *covers: str, commands: bool = False, namespace: str = ""
) -> tuple[GatedBridge, Blackboard, VirtualClock]:
    clock = VirtualClock()
    catalogue = default_catalogue()
    stream = SessionStream(clock)
    gates = ConsentGates(stream, Consent("kid-17", frozenset(covers)))
    plan = Ros2Plan(lab.endpoint, 0, commands, namespace=namespace)
    bridge = Ros2Bridge(plan, clock, 1.7e9, gates.sending, catalogue)
    gates.sent.subscribe(bridge)
    board = Blackboard(catalogue, clock)
    bridge.start(board)
    return GatedBridge(bridge, stream), board, clock


HUG = TreeStarted(
    0.0,
    "hug",
    1,
    Path("trees/hug.yaml"),
    (Path("trees/hug.yaml"),),
    20.0,
    50,
    (NodeInfo(0, "hug", "Sequence", "Sequence", 0), NodeInfo(1, "hug/0", "IsSqueezed", "", 1)),
    "",
)


def test_a_ros2_node_sees_vest_its_topics_and_each_tree_s_behavior_tree_log(lab: Lab) -> None:
    bridge, _, _ = bridge_on(lab, "sensors", "cloud_telemetry")
    try:
        bridge.on_event(HUG)
        bridge.on_event(NodeStatus(0.05, "hug", 1, 1, 1, "RUNNING", ""))
        bridge.on_event(NodeStatus(0.10, "hug", 1, 2, 1, "SUCCESS", ""))
        bridge.on_event(KeyChanged(0.10, FORCE_LEFT_N, 12.5, "12.5", False, "force"))
        bridge.on_event(KeyChanged(0.10, TOUCH_ANY, True, "true", False, "touch"))
        log_type = "nav2_msgs/msg/BehaviorTreeLog"
        logs = lab.wait_for("hug's log", lambda: lab.messages("/vest/trees/hug/log", log_type))
        force = lab.wait_for(
            "the force", lambda: lab.messages("/vest/sensors/force/left_n", "std_msgs/msg/Float64")
        )
        touched = lab.wait_for(
            "a touch", lambda: lab.messages("/vest/sensors/touch/any", "std_msgs/msg/Bool")
        )
        tokens = lab.wait_for(
            "the node", lambda: [t for t in lab.tokens if t.endswith("/NN/%/%/vest")]
        )
    finally:
        bridge.stop()
    changes = [(c.node_name, c.uid, c.previous_status, c.current_status) for c in logs[0].event_log]
    assert changes == [("hug/0", 2, "IDLE", "RUNNING"), ("hug/0", 2, "RUNNING", "SUCCESS")]
    assert logs[0].event_log[0].timestamp.sec == 1_700_000_000
    assert force[0].data == 12.5 and touched[0].data is True
    assert tokens, "ros2 node list would not show /vest"
    publishers = [t for t in lab.tokens if "/MP/" in t]
    assert any(
        "/%vest%sensors%force%left_n/std_msgs::msg::dds_::Float64_/RIHS01_" in t for t in publishers
    )
    with lab.arrived:
        sequences = [extra for key, _, extra in lab.samples if "/trees/hug/log/" in key]
    assert sequences[0] is not None and len(sequences[0]) == 8 + 8 + 1 + 16  # rmw_zenoh's


def test_without_telemetry_consent_no_reading_leaves_the_robot(lab: Lab) -> None:
    bridge, _, _ = bridge_on(lab, "sensors")  # may be recorded, never sent
    try:
        bridge.on_event(KeyChanged(0.1, FORCE_LEFT_N, 12.5, "12.5", False, "force"))
        bridge.on_event(KeyChanged(0.1, "/devices/leds/color", "pink", '"pink"', False, "leds"))
        lab.wait_for("the LEDs' color", lambda: lab.messages("/vest/devices/leds/color", STRING))
    finally:
        bridge.stop()
    with lab.arrived:
        assert not [key for key, _, _ in lab.samples if "/sensors/" in key]


def test_a_command_from_the_graph_goes_the_cloud_s_way_and_its_result_comes_back(
    lab: Lab,
) -> None:
    bridge, board, _ = bridge_on(lab, "sensors", "cloud_telemetry", commands=True)
    try:
        lab.listening_for_commands()
        lab.send(json.dumps({"id": "wave-1", "type": "say", "args": {"text": "hello"}}))
        lab.wait_for("the command taken", lab.results)
        board.commit()
        staged = board.event_log(IOT_INBOX).latest
        assert staged is not None
        assert staged.value == {"id": "ros2:wave-1", "type": "say", "args": {"text": "hello"}}
        report = {"id": "ros2:wave-1", "status": "succeeded", "result": None}
        bridge.on_event(ActionStarted(1.0, 7, "iot_command", "report", report))
        results = lab.two_results("the result")
    finally:
        bridge.stop()
    assert [(r["id"], r["status"]) for r in results] == [
        ("wave-1", "RECEIVED"),
        ("wave-1", "SUCCEEDED"),
    ]


@pytest.mark.parametrize(
    ("sent", "why"),
    [
        ("say hello", "not JSON"),
        ("[" * 1000 + "]" * 1000, "nests at most 8 levels"),
        ('["say"]', "a command is a JSON object"),
        ('{"type": "dance"}', "type: one of say, led, move, read"),
        ('{"type": "say", "args": {"text": "hi", "volume": 5}}', "'volume'"),
        ('{"type": "led", "args": {"color": "blurple"}}', "unknown color"),
        ('{"type": "say", "id": "../../x", "args": {"text": "hi"}}', "id: 1 to 64"),
    ],
)
def test_a_command_the_robot_would_refuse_is_refused_at_once(lab: Lab, sent: str, why: str) -> None:
    bridge, board, _ = bridge_on(lab, commands=True)
    try:
        lab.listening_for_commands()
        lab.send(sent)
        results = lab.wait_for("the refusal", lab.results)
    finally:
        bridge.stop()
    assert results[0]["status"] == "REFUSED" and why in results[0]["result"]["error"]
    board.commit()
    assert board.event_log(IOT_INBOX).latest is None


def test_a_read_without_telemetry_consent_answers_failed_never_the_reading(lab: Lab) -> None:
    bridge, _, _ = bridge_on(lab, "sensors", commands=True)
    try:
        lab.listening_for_commands()
        lab.send(json.dumps({"id": "r1", "type": "read", "args": {"sensor": "force"}}))
        lab.wait_for("the command taken", lab.results)
        reading = {FORCE_LEFT_N: 12.5}
        report = {"id": "ros2:r1", "status": "succeeded", "result": reading}
        bridge.on_event(ActionStarted(1.0, 7, "iot_command", "report", report))
        results = lab.two_results("the result")
        actions = lab.wait_for("the report", lambda: lab.messages("/vest/actions", STRING))
    finally:
        bridge.stop()
    assert results[1]["status"] == "FAILED" and "12.5" not in json.dumps(results[1])
    assert "consent does not cover" in results[1]["result"]["error"]
    action = json.loads(actions[0].data)["args"]  # what the robot did, not what it read
    assert action["id"] == "ros2:r1" and "12.5" not in actions[0].data


def test_telemetry_consent_without_sensors_sends_no_reading_either(lab: Lab) -> None:
    bridge, _, _ = bridge_on(lab, "cloud_telemetry", commands=True)
    try:
        lab.listening_for_commands()
        lab.send(json.dumps({"id": "r2", "type": "read", "args": {"sensor": "force"}}))
        lab.wait_for("the command taken", lab.results)
        report = {"id": "ros2:r2", "status": "succeeded", "result": {FORCE_LEFT_N: 12.5}}
        bridge.on_event(ActionStarted(1.0, 7, "iot_command", "report", report))
        results = lab.two_results("the result")
    finally:
        bridge.stop()
    assert results[1]["status"] == "FAILED" and "12.5" not in json.dumps(results)


def test_a_command_still_waiting_when_the_robot_stops_is_told_lost(lab: Lab) -> None:
    bridge, _, _ = bridge_on(lab, commands=True)
    try:
        lab.listening_for_commands()
        lab.send(json.dumps({"type": "say", "args": {"text": "hello"}}))  # no id: one is given
        lab.wait_for("the command taken", lab.results)
    finally:
        bridge.stop()
    results = lab.two_results("its end")
    assert [r["status"] for r in results] == ["RECEIVED", "LOST"]
    assert results[0]["id"] == results[1]["id"] == "n1"
    assert "stopped" in results[1]["result"]["error"]


def test_a_second_command_under_a_waiting_id_is_refused(lab: Lab) -> None:
    bridge, _, _ = bridge_on(lab, commands=True)
    try:
        lab.listening_for_commands()
        for _ in range(2):
            lab.send(json.dumps({"id": "same", "type": "say", "args": {"text": "hi"}}))
        results = lab.two_results("both answers")
    finally:
        bridge.stop()
    assert [r["status"] for r in results[:2]] == ["RECEIVED", "REFUSED"]
    assert "still waiting" in results[1]["result"]["error"]


def test_two_robots_on_one_graph_keep_to_their_own_namespaces(lab: Lab) -> None:
    def leds_of(robot: str) -> Callable[[], list[Any]]:
        return lambda: lab.messages(f"/{robot}/vest/devices/leds/color", STRING)

    left, _, _ = bridge_on(lab, namespace="hbs2")
    right, _, _ = bridge_on(lab, namespace="hbs3")
    try:
        left.on_event(KeyChanged(0.1, "/devices/leds/color", "pink", '"pink"', False, "leds"))
        right.on_event(KeyChanged(0.1, "/devices/leds/color", "blue", '"blue"', False, "leds"))
        colors = {robot: lab.wait_for(robot, leds_of(robot)) for robot in ("hbs2", "hbs3")}
    finally:
        left.stop()
        right.stop()
    assert {robot: [m.data for m in found] for robot, found in colors.items()} == {
        "hbs2": ["pink"],
        "hbs3": ["blue"],
    }
    nodes = sorted(token.split("/NN/")[1] for token in lab.tokens if "/NN/" in token)
    assert nodes == ["%/%hbs2/vest", "%/%hbs3/vest"]  # /hbs2/vest and /hbs3/vest


def test_without_ros2_commands_the_robot_takes_none(lab: Lab) -> None:
    bridge, board, _ = bridge_on(lab)
    try:
        bridge.on_event(KeyChanged(0.1, "/devices/leds/color", "pink", '"pink"', False, "leds"))
        lab.wait_for("the node's first topic", lambda: [t for t in lab.tokens if "/MP/" in t])
        lab.send(json.dumps({"type": "say", "args": {"text": "hello"}}))
    finally:
        bridge.stop()
    assert not [t for t in lab.tokens if "/MS/" in t]  # nobody listens on /vest/command
    board.commit()
    assert board.event_log(IOT_INBOX).latest is None


def test_vest_run_carries_out_a_say_sent_from_the_graph(lab: Lab) -> None:
    on_the_graph = ["--ros2", lab.endpoint, "--ros2-commands"]
    robot = subprocess.Popen(
        [*VEST, "run", "--speech", "text", "--duration", "60", *on_the_graph],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert robot.stderr is not None
        said = next(line for line in robot.stderr if line.startswith("ros2: "))
        # the robot's namespace is its config's name (the simulated vest's: sim)
        assert "node /sim/vest on domain 0" in said and "commands on /sim/vest/command" in said
        lab.prefix = "/sim"
        lab.listening_for_commands()
        lab.send(json.dumps({"id": "hello-1", "type": "say", "args": {"text": "hello there"}}))
        results = lab.two_results("the say's result")
        log_type = "nav2_msgs/msg/BehaviorTreeLog"
        iot_log = lab.messages("/sim/vest/trees/iot_command/log", log_type)
    finally:
        robot.terminate()
        robot.wait(timeout=60)
    assert [(r["id"], r["status"]) for r in results[:2]] == [
        ("hello-1", "RECEIVED"),
        ("hello-1", "SUCCEEDED"),
    ]
    assert any(c.current_status == "SUCCESS" for m in iot_log for c in m.event_log)


@pytest.mark.parametrize(
    ("options", "environment", "said"),
    [
        (["--ros2", "nonsense"], {}, r"--ros2 'nonsense': the router's Zenoh endpoint"),
        (["--ros2", 'tcp/1.2.3.4:7447"]'], {}, r"the router's Zenoh endpoint"),
        (["--ros2", "tcp/127.0.0.1:99999"], {}, r"a port 1..65535"),
        (["--ros2"], {"ZENOH_SESSION_CONFIG_URI": "/dev/zero"}, r"/dev/zero: not a file"),
        (["--ros2-commands"], {}, r"--ros2-commands .* add --ros2"),
        (["--ros2-namespace", "hbs2"], {}, r"--ros2-namespace names .* add --ros2"),
        (["--ros2", "--ros2-namespace", "2fast"], {}, r"'2fast' is not a ROS 2 namespace"),
        (["--ros2", "--ros2-namespace", "a b"], {}, r"'a b' is not a ROS 2 namespace"),
        (["--ros2"], {"ROS_DOMAIN_ID": "abc"}, r"ROS_DOMAIN_ID='abc': a number 0..232"),
        (["--ros2"], {"ZENOH_SESSION_CONFIG_URI": "/no/such.json5"}, r"cannot read it"),
        (["--ros2", "--ros2-commands", "--trees", "trees/hug.yaml"], {}, r"no tree carries"),
    ],
)
def test_a_graph_vest_cannot_join_is_named_in_one_line(
    options: list[str], environment: dict[str, str], said: str
) -> None:
    done = subprocess.run(
        [*VEST, "run", "--fast", "--duration", "1", *options],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=os.environ | environment,
        timeout=120,
    )
    assert done.returncode != 0
    assert re.search(said, done.stderr) and "Traceback" not in done.stderr
