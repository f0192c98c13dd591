"""Consent holds on every path out of the robot. One session per consent, with every exit
open at once: a child squeezes the robot twice and says "my brother hits me every night";
one tree echoes part of what it heard ("I think you said {/vars/heard:.15}"), another says
how hard it was squeezed ("You squeezed with {...:.1f} newtons", cut short by the echo,
then yielding to it), the dialog does not understand, and an operator reads the force
sensor through the cloud while it is squeezed. Every byte that left by each exit is
searched for the child's words and for the readings:

- kept on the site: the recording (every table), its report, the export, the `--json`
  timeline, the terminal's timeline, the live view's stream and Foxglove's;
- sent off the robot: the cloud's telemetry and the read's result, a ROS 2 graph.

Full consent is the control: there, every exit carries both (the search finds them)."""

from __future__ import annotations

import json
import re
import socket
import struct
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import requests
from websockets.sync.client import connect

from cloud.settings import Settings
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording
from engine.recording.session_file import TABLES
from tests.cloud.conftest import Running, start_service  # noqa: F401 - the fixture

pytestmark = pytest.mark.realtime

zenoh = pytest.importorskip("zenoh")  # the ros2 extra

ROOT = Path(__file__).resolve().parents[2]
VEST = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
WORDS = re.compile(rb"brother|hits me|every night", re.IGNORECASE)
LISTENS = """\
name: listens
rate_hz: 20
priority: 60
wake_on: [/speech/heard]
root:
  Sequence:
    - OnEvent: {key: /speech/heard, save_as: /vars/heard}
    - Say: {text: "I think you said {/vars/heard:.15}"}
"""
SQUEEZES = """\
name: squeezes
rate_hz: 20
priority: 50
root:
  Sequence:
    - OnEvent: {key: /sensors/force/squeeze}
    - Say: {text: "You squeezed with {/sensors/force/left_n:.1f} newtons"}
"""
SCENARIO = """\
duration_s: 11
events:
  - {at: 1.5, squeeze: {left_n: 8.3, right_n: 8.3, seconds: 1.6}}
  - {at: 2.0, hear: {text: "my brother hits me every night"}}
  - {at: 6.0, squeeze: {left_n: 8.3, right_n: 8.3, seconds: 1.6}}
"""
"""The second squeeze comes once the robot has said what it heard: on a loaded machine
the first and the words can reach the trees at one tick, and then the words (a higher
priority) take the speaker and the first squeeze is never put in words."""
KEPT = ("recording", "report", "export", "json", "timeline", "view", "foxglove")
SENT = ("cloud", "ros2")
WORDS_SENT = ("ros2", "cloud")
"""What was heard leaves with consent: on ROS 2, and in the session the cloud's page shows
(its "what happened"; the cloud's telemetry is the sensors and devices)."""


FORCE_N = 8.375000000000014
"""The left pad's force as the simulated FSR and ADS1115 read a squeeze of 8.3 N."""
READINGS = re.compile(
    re.escape(b"8.375") + b"|" + re.escape(struct.pack("<d", FORCE_N)) + b"|squeezed with 8"
)
"""The squeeze as read: the force as JSON or text, as a ROS 2 Float64 (eight bytes), or
in the robot's words ("You squeezed with 8.4 newtons")."""


class Graph:
    """A Zenoh peer where the robot's ROS 2 node publishes: keeps every byte it is sent."""

    def __init__(self) -> None:
        probe = socket.socket()
        probe.bind(("127.0.0.1", 0))
        self.endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
        probe.close()
        from engine.interop.ros2_wire import session_config

        self.session = zenoh.open(session_config(None, None, listen=self.endpoint))
        self.received = bytearray()
        self._subscriber = self.session.declare_subscriber("**", self._take)

    def _take(self, sample: Any) -> None:
        self.received += sample.payload.to_bytes()


@pytest.fixture
def graph() -> Iterator[Graph]:
    peer = Graph()
    yield peer
    peer.session.close()


def _read_stream(address: str, into: bytearray) -> None:
    """The live view's stream, as a page reads it, until the session ends."""
    base, _, query = address.partition("?")
    with requests.get(f"{base}api/events?{query}", stream=True, timeout=60) as answer:
        for chunk in answer.iter_content(chunk_size=None):
            into += chunk


def _read_foxglove(address: str, into: bytearray) -> None:
    """Foxglove: every channel subscribed as it is advertised, every frame kept."""
    with connect(address, subprotocols=["foxglove.websocket.v1"], open_timeout=10) as client:
        while True:
            try:
                frame = client.recv(timeout=30)
            except Exception:  # the session ended and closed it
                return
            into += frame if isinstance(frame, bytes) else frame.encode()
            if isinstance(frame, str) and '"advertise"' in frame:
                channels = json.loads(frame)["channels"]
                wanted = [{"id": c["id"], "channelId": c["id"]} for c in channels]
                client.send(json.dumps({"op": "subscribe", "subscriptions": wanted}))


def session_under(
    covers: str,
    tmp_path: Path,
    start_service: Callable[..., Running],  # noqa: F811 - the fixture
    graph: Graph,
    the_site_key: SiteKey,
) -> dict[str, bytes]:
    """kid-17's session under a consent covering ``covers``: every byte of every exit."""
    from engine.cli import main

    if covers:
        assert (
            main(["data", "consent", "kid-17", "--given-by", "guardian", "--covers", covers]) == 0
        )
    folder = tmp_path / covers.replace(",", "-") if covers else tmp_path / "nothing"
    (folder / "trees").mkdir(parents=True)
    (folder / "trees" / "listens.yaml").write_text(LISTENS)
    (folder / "trees" / "squeezes.yaml").write_text(SQUEEZES)
    (folder / "scenario.yaml").write_text(SCENARIO)
    trees = [str(folder / "trees"), str(ROOT / "trees/dialog.yaml")]
    trees.append(str(ROOT / "trees/iot_command.yaml"))

    cloud = start_service(Settings(db_url=f"sqlite:///{folder / 'cloud.db'}"))
    sent_to_cloud = bytearray()
    put = cloud.store.telemetry.put

    def kept_put(robot_id: int, values: dict[str, Any]) -> None:  # every push, as it came
        sent_to_cloud.extend(json.dumps(values).encode())
        put(robot_id, values)

    cloud.store.telemetry.put = kept_put  # type: ignore[method-assign]
    shown = cloud.store.sessions.put

    def kept_view(robot_id: int, view: dict[str, Any]) -> None:  # the cloud page's session
        sent_to_cloud.extend(json.dumps(view).encode())
        shown(robot_id, view)

    cloud.store.sessions.put = kept_view  # type: ignore[method-assign]
    cloud.store.directory.add_operator("ana")
    token = folder / "robot.token"
    token.write_text(cloud.store.directory.add_robot("hbs2", operator="ana") + "\n")
    robot = cloud.store.directory.authenticate(token.read_text().strip())

    recording = folder / "session.vest"
    command = [*VEST, "run", "--trees", *trees, "--scenario", str(folder / "scenario.yaml")]
    command += ["--speech", "text", "--person", "kid-17", "--record", str(recording), "--json"]
    command += ["--view", "--view-port", "0", "--foxglove", "0", "--ros2", graph.endpoint]
    command += ["--cloud", cloud.url, "--token-file", str(token)]
    running = subprocess.Popen(
        command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    view, foxglove = bytearray(), bytearray()
    readers: list[threading.Thread] = []
    assert running.stderr is not None and running.stdout is not None
    for line in running.stderr:  # the view and Foxglove are up before the first tick
        for prefix, read, into in (
            ("view: ", _read_stream, view),
            ("foxglove: ", _read_foxglove, foxglove),
        ):
            if line.startswith(prefix):
                address = line.removeprefix(prefix).split()[0]
                readers.append(threading.Thread(target=read, args=(address, into), daemon=True))
                readers[-1].start()
        if len(readers) == 2:
            break
    json_lines = []
    read = None
    for line in running.stdout:
        json_lines.append(line)
        if read is None and '"tree": "squeezes"' in line:  # squeezed: the operator asks
            read, _ = cloud.store.ledger.submit(robot.id, "read", {"sensor": "force"})
    running.wait(timeout=60)
    for reader in readers:
        reader.join(timeout=30)
    assert running.returncode == 0, running.stderr.read()
    assert read is not None
    result = cloud.store.ledger.get(robot.id, read.id)
    sent_to_cloud += json.dumps([result.state, result.result]).encode()

    key = the_site_key
    opened = Recording.open(recording, key)
    try:
        tables = json.dumps({name: opened.table(name) for name in (*TABLES, "events")}).encode()
    finally:
        opened.close()
    assert main(["report", str(recording), "-o", str(folder / "report.html")]) == 0
    exported = folder / "export"
    assert main(["data", "export", "--person", "kid-17", "-o", str(exported)]) == 0
    export = b"".join(path.read_bytes() for path in sorted(exported.rglob("*")) if path.is_file())
    fast = ["--fast", "--speech", "text", "--person", "kid-17"]  # the whole scenario
    timeline = subprocess.run(
        [*VEST, "run", *fast, "--trees", *trees, "--scenario", str(folder / "scenario.yaml")],
        cwd=ROOT,
        capture_output=True,
        check=True,
    ).stdout
    return {
        "recording": tables,
        "report": (folder / "report.html").read_bytes(),
        "export": export,
        "json": "".join(json_lines).encode(),
        "timeline": timeline,
        "view": bytes(view),
        "foxglove": bytes(foxglove),
        "cloud": bytes(sent_to_cloud),
        "ros2": bytes(graph.received),
    }


@pytest.mark.parametrize(
    ("covers", "words_in", "readings_in"),
    [
        ("sensors,speech_text,cloud_telemetry", KEPT + WORDS_SENT, KEPT + SENT),  # the control
        ("sensors", (), KEPT),
        ("speech_text,cloud_telemetry", KEPT + WORDS_SENT, ()),
        ("", (), ()),  # no record: readings are kept, nothing is sent
    ],
)
def test_what_leaves_by_each_exit_is_what_the_child_s_consent_allows(
    covers: str,
    words_in: tuple[str, ...],
    readings_in: tuple[str, ...],
    tmp_path: Path,
    start_service: Callable[..., Running],  # noqa: F811 - the fixture
    graph: Graph,
    the_site_key: SiteKey,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(ROOT)
    if not covers:  # a person with no consent record keeps sensor readings
        readings_in = KEPT
    left = session_under(covers, tmp_path, start_service, graph, the_site_key)
    for exit_, found in left.items():
        assert found, f"nothing came by {exit_}"
        heard = WORDS.findall(found)
        read = READINGS.findall(found)
        assert bool(heard) == (exit_ in words_in), (exit_, heard[:3])
        assert bool(read) == (exit_ in readings_in), (exit_, read[:3])


def test_the_consent_gate_is_the_only_reader_of_the_robot_s_own_stream(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, graph: Graph
) -> None:
    """Every way out is behind the gate: a session with all of them open has the gate as
    the one reader of what the robot tells, the others read its exits."""
    from engine.cli import main
    from engine.composition.session_root import RunningSession

    readers: dict[str, list[str]] = {}
    close = RunningSession.close

    def noting(running: RunningSession) -> None:  # as it stops, every part still there
        def names(stream: Any) -> list[str]:
            return sorted(type(reader).__name__ for reader in stream.readers)

        readers["robot"] = names(running.assembled.robot.session)
        readers["kept"] = names(running.gates.kept)
        readers["sent"] = names(running.gates.sent)
        close(running)

    monkeypatch.setattr(RunningSession, "close", noting)
    monkeypatch.chdir(ROOT)
    args = ["run", "--fast", "--speech", "text", "--duration", "2", "--json"]
    args += ["--record", str(tmp_path / "s.vest"), "--view", "--view-port", "0"]
    args += ["--foxglove", "0", "--ros2", graph.endpoint]
    assert main(args) == 0
    assert readers["robot"] == ["ConsentGates"]
    assert readers["kept"] == ["FoxgloveLive", "SessionRecorder", "Timeline", "ViewHub"]
    assert readers["sent"] == ["Ros2Bridge"]
