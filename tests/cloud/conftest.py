"""The cloud tests' databases: each test that takes ``db_url`` runs twice, on a fresh
SQLite file and on a fresh database of a throwaway PostgreSQL cluster (Debian's server
binaries, initdb in a temporary folder, pg_ctl on a free loopback port, stopped and removed
when the tests end). As root the cluster runs as the ``postgres`` user (the server refuses
to run as root). A missing PostgreSQL fails the tests: scripts/setup installs it."""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from cloud.app import create_app
from cloud.server import CloudServer
from cloud.services import CloudStore
from cloud.settings import Settings
from cloud.store.database import Database
from cloud.store.directory import Directory
from cloud.store.ledger import CommandLedger
from cloud.throwaway_postgres import PostgresCluster
from engine.clock import Clock, EpochClock, VirtualClock
from engine.web.serving import ServerThread, listening_socket


@pytest.fixture(scope="session")
def postgres() -> Iterator[PostgresCluster]:
    cluster = PostgresCluster()
    cluster.start()
    yield cluster
    cluster.stop()


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'cloud.db'}"
    cluster: PostgresCluster = request.getfixturevalue("postgres")
    return cluster.new_database()


@pytest.fixture
def clock() -> VirtualClock:
    return VirtualClock(start_s=1000.0)


@pytest.fixture
def db(db_url: str) -> Iterator[Database]:
    database = Database(db_url)
    yield database
    database.close()


@pytest.fixture
def directory(db: Database, clock: VirtualClock) -> Directory:
    return Directory(db, clock)


@pytest.fixture
def ledger(db: Database, clock: VirtualClock) -> CommandLedger:
    return CommandLedger(db, clock, lease_s=30.0, default_timeout_s=300.0)


@dataclass
class Running:
    """A service answering on loopback: its base URL (…/api/v1 is ``api``) and its store."""

    url: str
    store: CloudStore

    @property
    def api(self) -> str:
        return f"{self.url}/api/v1"


StartService = Callable[..., Running]


@pytest.fixture
def start_service() -> Iterator[StartService]:
    """Starts real uvicorn servers on free loopback ports (stopped after the test).

    Each is up when started: the one server thread the robot's pages use
    (:class:`engine.web.serving.ServerThread`), with the service's own uvicorn server."""
    running: list[tuple[ServerThread, CloudStore]] = []

    def start(settings: Settings, clock: Clock | None = None) -> Running:
        store = CloudStore.open(settings, clock or EpochClock())
        sock = listening_socket("127.0.0.1", 0)
        app = create_app(settings, store=store)
        server = ServerThread(app, sock, "cloud", lambda config: CloudServer(config, store))
        server.start()
        running.append((server, store))
        return Running(f"http://127.0.0.1:{server.port}", store)

    yield start
    for server, store in running:
        server.stop()
        store.close()


VEST = [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]
ROOT = Path(__file__).resolve().parents[2]


class Robot:
    """`vest run --cloud` on the simulated vest, its timeline read line by line (on a thread
    of its own, so a test that does not read it never leaves the robot blocked on a full
    pipe)."""

    def __init__(
        self,
        url: str,
        token_file: Path,
        scenario: Path,
        trees: list[str],
        person: str = "",
        buttons: str = "",
    ) -> None:
        whose = ["--person", person] if person else []  # their consent decides the telemetry
        board = ["--buttons", buttons, "--view-port", "0"] if buttons else []
        self.process = subprocess.Popen(
            [
                *VEST,
                "run",
                "--trees",
                *trees,
                "--scenario",
                str(scenario),
                "--speech",
                "text",
                "--cloud",
                url,
                "--token-file",
                str(token_file),
                "--json",
                *whose,
                *board,
            ],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        self.actions: list[dict[str, Any]] = []
        """The robot's actions, as --json tells them."""
        self.events: list[dict[str, Any]] = []
        """Every --json line (actions, how they ended, turns, safety...), once finished."""
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self._lines.put(line)
        self._lines.put(None)

    def until(self, wanted: Any) -> dict[str, Any]:
        """Reads the timeline until an action for which ``wanted(action)`` is true."""
        while (line := self._lines.get(timeout=120)) is not None:
            action = json.loads(line)
            self.events.append(action)
            if action["event"] != "action":
                continue  # the session's other events
            self.actions.append(action)
            if wanted(action):
                return action
        self._lines.put(None)  # the end stays the end for a later call
        raise AssertionError(f"the robot ended first; it did {self.actions}")

    def finish(self) -> list[dict[str, Any]]:
        self.process.wait(timeout=60)
        self._reader.join(timeout=10)
        while (line := self._lines.get_nowait()) is not None:
            if line.strip():
                self.events.append(json.loads(line))
                if self.events[-1]["event"] == "action":
                    self.actions.append(self.events[-1])
        assert self.process.returncode == 0
        return self.actions

    def said(self) -> list[str]:
        return [a["args"]["text"] for a in self.actions if a["action"] == "say"]


@pytest.fixture
def start_robot() -> Iterator[Callable[..., Robot]]:
    """Starts `vest run --cloud` robots on the simulated vest (stopped after the test)."""
    robots: list[Robot] = []

    def start(*args: Any, **kwargs: Any) -> Robot:  # as Robot takes them
        robots.append(Robot(*args, **kwargs))
        return robots[-1]

    yield start
    for robot in robots:
        if robot.process.poll() is None:
            robot.process.kill()
            robot.process.wait()


def self_signed(folder: Path) -> tuple[Path, Path]:
    """A throwaway self-signed certificate for 127.0.0.1 and its key (PEM, unencrypted),
    made with the openssl command."""
    cert, key = folder / "cert.pem", folder / "key.pem"
    subprocess.run(
        ["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256",
         "-nodes", "-keyout", str(key), "-out", str(cert), "-days", "1",
         "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"],
        check=True, capture_output=True,
    )  # fmt: skip
    return cert, key
