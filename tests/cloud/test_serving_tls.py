"""`vest cloud serve` speaks HTTPS itself (--certfile/--keyfile, one process or several), and
behind a reverse proxy believes the proxy's X-Forwarded-For only from the addresses it is
told to (--forwarded-allow-ips), so the audit log names the real client. The certificate is
a throwaway self-signed one made with the openssl command; every server is a real
`vest cloud serve` on loopback."""

from __future__ import annotations

import os
import socket
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
import requests

from cloud.services import CloudStore
from cloud.settings import Settings
from cloud.throwaway_postgres import PostgresCluster
from engine.cli import main
from engine.clock import EpochClock
from tests.cloud.conftest import ROOT, VEST, self_signed

pytestmark = pytest.mark.realtime


@pytest.fixture(scope="module")
def certificate(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A self-signed certificate for 127.0.0.1 and its key (PEM, unencrypted)."""
    return self_signed(tmp_path_factory.mktemp("tls"))


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


class Serving:
    """`vest cloud serve ARGS` in a process of its own, on a free loopback port; up once
    it said where operators open it (its socket listens before it says so)."""

    def __init__(self, db: str, *args: str) -> None:
        self.port = free_port()
        self.process = subprocess.Popen(
            [*VEST, "cloud", "serve", "--db", db, "--port", str(self.port), *args],
            cwd=ROOT,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
        )
        assert self.process.stderr is not None
        for line in self.process.stderr:
            if "operators open" in line:
                self.said = line
                return
        raise AssertionError(f"vest cloud serve ended ({self.process.wait()})")

    def stop(self) -> None:
        self.process.terminate()
        self.process.communicate(timeout=30)


@pytest.fixture
def serving() -> Iterator[list[Serving]]:
    started: list[Serving] = []
    yield started
    for one in started:
        one.stop()


def add_operator(db: str) -> str:
    store = CloudStore.open(Settings(db_url=db), EpochClock())
    try:
        store.directory.add_operator("ana")
        token = store.directory.add_operator("ada", role="admin")
        store.directory.add_robot("hbs2", operator="ana")
        return token
    finally:
        store.close()


def test_the_service_speaks_https_with_its_certificate(
    tmp_path: Path, certificate: tuple[Path, Path], serving: list[Serving]
) -> None:
    db = f"sqlite:///{tmp_path / 'c.db'}"
    token = add_operator(db)
    cert, key = certificate
    serving.append(Serving(db, "--certfile", str(cert), "--keyfile", str(key)))
    url = f"https://127.0.0.1:{serving[0].port}"
    assert f"operators open {url}/" in serving[0].said
    answer = requests.get(
        f"{url}/api/v1/robots",
        headers={"Authorization": f"Bearer {token}"},
        verify=str(cert),
        timeout=10,
    )
    assert answer.status_code == 200 and [r["name"] for r in answer.json()] == ["hbs2"]
    with pytest.raises(requests.exceptions.SSLError):  # a client that does not trust it
        requests.get(f"{url}/", timeout=10)
    with pytest.raises(requests.exceptions.ConnectionError):  # no plain HTTP on that port
        requests.get(f"http://127.0.0.1:{serving[0].port}/", timeout=10)


def test_several_workers_speak_https_too(
    postgres: PostgresCluster, certificate: tuple[Path, Path], serving: list[Serving]
) -> None:
    db = postgres.new_database()
    token = add_operator(db)
    cert, key = certificate
    serving.append(Serving(db, "--workers", "2", "--certfile", str(cert), "--keyfile", str(key)))
    for _ in range(4):
        answer = requests.get(
            f"https://127.0.0.1:{serving[0].port}/api/v1/me",
            headers={"Authorization": f"Bearer {token}"},
            verify=str(cert),
            timeout=30,
        )
        assert answer.json()["role"] == "admin"


@pytest.mark.parametrize(
    ("trusted", "client"),
    [
        (["--forwarded-allow-ips", "127.0.0.1"], "203.0.113.9"),
        (["--forwarded-allow-ips", ""], "127.0.0.1"),
    ],
)
def test_behind_a_trusted_proxy_the_audit_names_the_real_client(
    tmp_path: Path, serving: list[Serving], trusted: list[str], client: str
) -> None:
    """As nginx sends it (proxy_set_header X-Forwarded-For $proxy_add_x_forwarded_for): the
    address is believed only from a proxy the service was told to trust."""
    db = f"sqlite:///{tmp_path / 'c.db'}"
    token = add_operator(db)
    serving.append(Serving(db, *trusted))
    sent = requests.post(
        f"http://127.0.0.1:{serving[0].port}/api/v1/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hello"}},
        headers={
            "Authorization": f"Bearer {token}",
            "X-Forwarded-For": "203.0.113.9",
            "X-Forwarded-Proto": "https",
        },
        timeout=10,
    )
    assert sent.status_code == 201
    store = CloudStore.open(Settings(db_url=db), EpochClock())
    try:
        sends = [e for e in store.directory.audit.since() if e.action == "send"]
    finally:
        store.close()
    assert [(e.actor, e.client) for e in sends] == [("ada", client)]


@pytest.mark.parametrize(
    ("files", "message"),
    [
        (("missing", "key"), "--certfile {missing}: no such file"),
        (("key", "key"), "--certfile {key}: not a PEM certificate"),
        (("cert", "cert"), "--keyfile {cert}: not a PEM private key"),
        (("cert", "other"), "--keyfile {other}: not the private key of --certfile {cert}"),
        (("cert", None), "--certfile needs --keyfile too"),
    ],
)
def test_a_certificate_or_key_that_cannot_be_used_is_named_in_one_line(
    tmp_path: Path,
    certificate: tuple[Path, Path],
    capsys: pytest.CaptureFixture[str],
    files: tuple[str, str | None],
    message: str,
) -> None:
    cert, key = certificate
    other = tmp_path / "other.pem"
    subprocess.run(
        ["openssl", "genpkey", "-algorithm", "ec", "-pkeyopt", "ec_paramgen_curve:P-256",
         "-out", str(other)],
        check=True, capture_output=True,
    )  # fmt: skip
    paths = {"cert": str(cert), "key": str(key), "other": str(other)}
    paths["missing"] = str(tmp_path / "missing.pem")
    args = ["--certfile", paths[files[0]]]
    if files[1] is not None:
        args += ["--keyfile", paths[files[1]]]
    db = f"sqlite:///{tmp_path / 'c.db'}"
    assert main(["cloud", "serve", "--db", db, "--port", str(free_port()), *args]) == 1
    err = capsys.readouterr().err
    assert message.format(**paths) in err
    assert err.count("\n") == 1 and "Traceback" not in err
