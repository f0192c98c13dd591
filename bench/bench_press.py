"""How long a therapist's press takes to become the robot's action, from the next room
(through the cloud) and from beside the robot (its own buttons page, the baseline).

One `vest run --buttons --cloud --json` robot on the simulated vest (real time) and one
`vest cloud serve` on loopback (SQLite). The bench presses "Calm face" (an LED action)
again and again, a random 0.2-0.4 s apart, and times each press from just before its HTTP
request to the moment the robot's `--json` line for the LED action arrives on the bench's
pipe. Half the presses go through the cloud (`POST /api/v1/robots/hbs2/press` as a
therapist: the ledger, the robot's long-poll, the robot's buttons), half through the
robot's own page (`POST /api/press` on its view server), interleaved, so both meet the
same machine load. Target (issue 42): p99 <= 300 ms through the cloud.

    .venv/bin/python bench/bench_press.py              # 200 presses each way, ~3 min
    .venv/bin/python bench/bench_press.py --quick      # 10 each way: that it still runs
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import queue
import random
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
from pathlib import Path
from typing import IO

import requests

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from cloud.services import CloudStore  # noqa: E402
from cloud.settings import Settings  # noqa: E402
from engine.clock import EpochClock, RealClock  # noqa: E402
from engine.runtime.stats import percentile  # noqa: E402

VEST = [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]
BUTTON = "Calm face"
TARGET_P99_S = 0.300


CLOCK = RealClock()  # the one module that reads time and sleeps
HTTP = requests.Session()
HTTP.trust_env = False  # loopback, never through a proxy the environment names


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def wait_for(url: str, process: subprocess.Popen[str], log: Path, limit_s: float = 60.0) -> None:
    deadline = CLOCK.now() + limit_s
    while CLOCK.now() < deadline:
        if process.poll() is not None:
            raise SystemExit(f"{process.args[3:5]} ended: {log.read_text()[-2000:]}")
        try:
            HTTP.get(url, timeout=1)
            return
        except requests.RequestException:
            CLOCK.sleep(0.1)
    raise SystemExit(f"{url} never answered")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presses", type=int, default=200, help="presses each way")
    parser.add_argument("--quick", action="store_true", help="10 presses each way: it runs")
    args = parser.parse_args()
    if args.quick:
        args.presses = 10
    folder = Path(tempfile.mkdtemp(prefix="vest-press-"))
    with open(folder / "cloud.log", "w") as cloud_log, open(folder / "robot.log", "w") as robot_log:
        measure(folder, args.presses, cloud_log, robot_log)


def measure(folder: Path, presses: int, cloud_log: IO[str], robot_log: IO[str]) -> None:
    """Presses ``presses`` times each way; prints the figures."""
    db_url = f"sqlite:///{folder / 'cloud.db'}"
    store = CloudStore.open(Settings(db_url=db_url), EpochClock())
    store.directory.add_operator("ana")
    robot_token = store.directory.add_robot("hbs2", operator="ana")
    tess = store.directory.add_operator("tess", role="therapist")
    store.directory.grant("tess", "hbs2")
    store.close()
    (folder / "robot.token").write_text(robot_token + "\n")
    (folder / "long.yaml").write_text("duration_s: 86400\nevents: []\n")
    cloud_port, view_port = free_port(), free_port()
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    service = subprocess.Popen(
        [*VEST, "cloud", "serve", "--db", db_url, "--port", str(cloud_port)],
        cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=cloud_log,
    )  # fmt: skip
    cloud = f"http://127.0.0.1:{cloud_port}"
    wait_for(cloud, service, folder / "cloud.log")
    robot = subprocess.Popen(
        [*VEST, "run", "--trees", "trees/touch_thanks.yaml", "--scenario",
         str(folder / "long.yaml"), "--speech", "text", "--buttons",
         "trees/buttons/session.yaml", "--view-port", str(view_port), "--cloud", cloud,
         "--token-file", str(folder / "robot.token"), "--json"],
        cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=robot_log,
        text=True,
    )  # fmt: skip
    actions: queue.Queue[float] = queue.Queue()

    def read() -> None:
        assert robot.stdout is not None
        for line in robot.stdout:
            event = json.loads(line)
            if (
                event["event"] == "action"
                and event["action"] == "led"
                and event["tree"] == "buttons"
            ):
                actions.put(CLOCK.now())

    threading.Thread(target=read, daemon=True).start()
    local = f"http://127.0.0.1:{view_port}"
    wait_for(local, robot, folder / "robot.log")
    page_token = (folder / "robot.log").read_text().split("?token=")[1].split()[0]
    beside = {"Authorization": f"Bearer {page_token}"}  # the robot's own page's token
    therapist = {"Authorization": f"Bearer {tess}"}
    deadline = CLOCK.now() + 60
    while HTTP.get(f"{cloud}/api/v1/robots/hbs2/session", headers=therapist).status_code != 200:
        assert CLOCK.now() < deadline, "the robot never sent its session"
        CLOCK.sleep(0.1)
    view = HTTP.get(f"{cloud}/api/v1/robots/hbs2/session", headers=therapist).json()["view"]
    number = [b["label"] for b in view["board"]["buttons"]].index(BUTTON)
    took: dict[str, list[float]] = {"cloud": [], "local": []}
    lost = {"cloud": 0, "local": 0}
    order = ["cloud", "local"] * presses
    random.Random(42).shuffle(order)
    try:
        for way in order:
            CLOCK.sleep(random.uniform(0.2, 0.4))
            while not actions.empty():  # a late line of an earlier press: not this one's
                actions.get_nowait()
            started = CLOCK.now()
            if way == "cloud":
                answer = HTTP.post(
                    f"{cloud}/api/v1/robots/hbs2/press", json={"button": number}, headers=therapist
                )
            else:
                answer = HTTP.post(f"{local}/api/press", json={"button": number}, headers=beside)
            assert answer.status_code == 202, answer.text
            try:
                took[way].append(actions.get(timeout=3.0) - started)
            except queue.Empty:
                lost[way] += 1
    finally:
        robot.send_signal(signal.SIGINT)
        robot.wait(30)
        service.send_signal(signal.SIGINT)
        service.wait(30)
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; {presses} presses each way")
    print("way     presses  p50 ms  p90 ms  p99 ms  max ms  lost")
    for way in ("local", "cloud"):
        values = took[way]
        print(
            f"{way:7} {len(values):7d} {statistics.median(values) * 1e3:7.1f} "
            f"{percentile(values, 0.90) * 1e3:7.1f} {percentile(values, 0.99) * 1e3:7.1f} "
            f"{max(values) * 1e3:7.1f} {lost[way]:5d}"
        )
    p99_cloud, p99_local = percentile(took["cloud"], 0.99), percentile(took["local"], 0.99)
    print(
        f"cloud / local p99: {p99_cloud / p99_local:.2f}; target p99 <= {TARGET_P99_S * 1e3:.0f} "
        f"ms through the cloud: {'met' if p99_cloud <= TARGET_P99_S else 'NOT met'}"
    )


if __name__ == "__main__":
    main()
