"""What watching and recording cost the robot: tick lateness and tick time with the live
view (a page connected and reading every change), with Foxglove's live server (a client
subscribed to every topic, reading every message), on a ROS 2 graph (``--ros2``: a Zenoh
peer of this process reading every message, the person's consent covering sensors and
telemetry so everything is sent) and with a recording, against the same run with none of
them, in one run.

Run: ``.venv/bin/python bench/bench_view.py`` (``--seconds S``, ``--rounds N``); about
4 minutes with the defaults (5 ways x 2 rounds x 20 s).

Each run is ``vest run --speech text`` on the demo scenario in real time (every tree of
trees/, the simulated vest with its poller threads), ``--duration S``; the ways are
interleaved round by round so a busy machine hurts them alike. From each run's summary
table: the worst tree's tick p99 and lateness p99 (ms). The view's page is a client that
reads the server-sent changes as a browser does (every one of them, parsed as JSON).

Target (issue 11): the view and the recording cost the tick nothing a person notices:
lateness p99 with them within 1 ms of the run without.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import requests

ROOT = Path(__file__).resolve().parents[1]
VEST = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
ROW = re.compile(r"^(\w+)\s+\d+/s\s+(\d+)\s+([\d.]+)ms\s+([\d.]+)ms\s+([\d.]+)ms\s+(\d+)$", re.M)


def read_changes(address: str, counted: list[int], stop: threading.Event) -> None:
    """A page: reads every change the view sends (with the token the address carries)."""
    base, _, query = address.partition("?")
    with requests.get(f"{base}api/events?{query}", stream=True, timeout=60) as response:
        for line in response.iter_lines():
            if stop.is_set():
                return
            if line.startswith(b"data: "):
                json.loads(line[6:])
                counted[0] += 1


def read_foxglove(address: str, counted: list[int], stop: threading.Event) -> None:
    """Foxglove: subscribes to every channel as it is advertised and reads every message."""
    from websockets.sync.client import connect

    with connect(address, subprotocols=["foxglove.sdk.v1"], open_timeout=10) as client:
        subscribed: set[int] = set()
        while not stop.is_set():
            try:
                frame = client.recv(timeout=1)
            except TimeoutError:
                continue
            except Exception:  # the run ended and closed the server
                return
            if isinstance(frame, bytes):
                json.loads(frame[13:])  # opcode, subscription, time, then the message
                counted[0] += 1
                continue
            message = json.loads(frame)
            if message.get("op") == "advertise":
                new = [c["id"] for c in message["channels"] if c["id"] not in subscribed]
                subscribed.update(new)
                wanted = [{"id": channel, "channelId": channel} for channel in new]
                client.send(json.dumps({"op": "subscribe", "subscriptions": wanted}))


class RosGraph:
    """A Zenoh peer that listens as rmw_zenoh's router would and counts what the robot
    publishes (the ros2 extra)."""

    def __init__(self) -> None:
        import socket

        import zenoh

        probe = socket.socket()
        probe.bind(("127.0.0.1", 0))
        self.endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
        probe.close()
        from engine.interop.ros2_wire import session_config

        self.session = zenoh.open(session_config(None, None, listen=self.endpoint))
        self.counted = [0]
        self._subscriber = self.session.declare_subscriber("0/vest/**", self._count)

    def _count(self, sample: object) -> None:
        self.counted[0] += 1


def run(way: str, seconds: float, folder: Path, graph: RosGraph | None = None) -> dict[str, float]:
    """One run of ``way``; a recording goes to a new file in ``folder`` (vest never
    replaces an earlier session)."""
    args = [*VEST, "run", "--speech", "text", "--duration", str(seconds)]
    if way == "record":
        args += ["--record", str(folder / f"bench-{len(list(folder.iterdir()))}.vest")]
    if way == "view":
        args += ["--view", "--view-port", "0"]
    if way == "foxglove":
        args += ["--foxglove", "0"]
    if way == "ros2" and graph is not None:
        args += ["--ros2", graph.endpoint, "--person", "bench-1"]
        graph.counted[0] = 0
    site = {"VEST_DATA": str(folder.parent / "site")}  # a site of its own: its key, its index
    process = subprocess.Popen(
        args,
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, **site},
    )
    counted, stop = [0], threading.Event()
    reader: threading.Thread | None = None
    if way in ("view", "foxglove"):
        assert process.stderr is not None
        prefix, target = (
            ("view: ", read_changes) if way == "view" else ("foxglove: ", read_foxglove)
        )
        for line in process.stderr:
            if line.startswith(prefix):
                address = line.removeprefix(prefix).split()[0]
                reader = threading.Thread(target=target, args=(address, counted, stop), daemon=True)
                reader.start()
                break
    out, err = process.communicate(timeout=seconds + 120)
    stop.set()
    if graph is not None and way == "ros2":
        counted = graph.counted
    rows = ROW.findall(out)
    if not rows:
        raise SystemExit(f"no statistics from vest run ({way}):\n{out[-2000:]}{err[-2000:]}")
    return {
        "tick_p99_ms": max(float(r[3]) for r in rows),
        "late_p99_ms": max(float(r[4]) for r in rows),
        "changes": float(counted[0]),
    }


def measure(
    ways: tuple[str, ...],
    results: dict[str, list[dict[str, float]]],
    graph: RosGraph,
    seconds: float,
    rounds: int,
) -> None:
    """Every way, round by round (interleaved: a busy machine hurts them alike)."""
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch) / "recordings"
        folder.mkdir()
        site = {"VEST_DATA": str(folder.parent / "site")}
        covers = ["--covers", "sensors,speech_text,cloud_telemetry"]
        consent = [*VEST, "data", "consent", "bench-1", "--given-by", "bench", *covers]
        subprocess.run(consent, cwd=ROOT, env={**os.environ, **site}, check=True)
        for round_number in range(rounds):
            for way in ways:
                results[way].append(run(way, seconds, folder, graph))
                print(f"round {round_number + 1} {way:7} {results[way][-1]}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="each run's length")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    args = parser.parse_args()
    if args.quick:
        args.seconds, args.rounds = 3.0, 1
    ways = ("plain", "record", "view", "foxglove", "ros2")
    results: dict[str, list[dict[str, float]]] = {way: [] for way in ways}
    graph = RosGraph()
    try:
        measure(ways, results, graph, args.seconds, args.rounds)
    finally:
        graph.session.close()  # its threads would keep the process alive
    base = {key: statistics.median(r[key] for r in results["plain"]) for key in results["plain"][0]}
    print(f"\nworst tree over {args.rounds} rounds of {args.seconds:g} s (median of rounds)")
    print(f"{'':8} {'tick p99 ms':>12} {'late p99 ms':>12} {'changes read':>13}")
    for way in ways:
        tick = statistics.median(r["tick_p99_ms"] for r in results[way])
        late = statistics.median(r["late_p99_ms"] for r in results[way])
        changes = statistics.median(r["changes"] for r in results[way])
        print(
            f"{way:8} {tick:12.3f} {late:12.3f} {changes:13.0f}"
            f"   lateness {late - base['late_p99_ms']:+.3f} ms vs plain"
        )


if __name__ == "__main__":
    main()
