"""The reverse-proxy example of docs/cloud.md, run: Debian's nginx (nginx-light, installed by
scripts/setup) with that very server block terminates TLS in front of the service on
loopback; a command sent through it is audited with the real client's address (not one
the client forged), and the operators' live stream passes through at once."""

from __future__ import annotations

import re
import shutil
import socket
import subprocess
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
import requests

from cloud.settings import Settings
from tests.cloud.conftest import ROOT, self_signed

pytestmark = pytest.mark.realtime

NGINX = shutil.which("nginx") or "/usr/sbin/nginx"
DOCS_BLOCK = re.compile(r"```nginx\n(.*?)```", re.S)


def docs_server_block(number: int = 0) -> str:
    """The ``number``-th nginx block of docs/cloud.md (0: one host, 1: several hosts)."""
    return str(DOCS_BLOCK.findall((ROOT / "docs" / "cloud.md").read_text())[number])


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def placed(block: str, replacements: dict[str, str]) -> str:
    """The docs' block with its addresses and files replaced by this test's (each must be
    there: a changed example fails here, not silently)."""
    for old, new in replacements.items():
        assert old in block, f"docs/cloud.md's nginx example no longer has {old!r}"
        block = block.replace(old, new)
    return block


@pytest.fixture
def proxy(
    tmp_path: Path, start_service: Callable[..., Any]
) -> Iterator[tuple[str, Any, str, Path]]:
    """nginx with the docs' server block in front of a service; (https url, the store,
    ana's token, the certificate the client trusts)."""
    assert Path(NGINX).exists(), "nginx is missing: run scripts/setup (apt nginx-light)"
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"))
    token = running.store.directory.add_operator("ana")
    running.store.directory.add_robot("hbs2", operator="ana")
    cert, key = self_signed(tmp_path)
    port = free_port()
    server = placed(
        docs_server_block(),
        {
            "listen 443 ssl;": f"listen 127.0.0.1:{port} ssl;",
            "/etc/letsencrypt/live/cloud.example.org/fullchain.pem": str(cert),
            "/etc/letsencrypt/live/cloud.example.org/privkey.pem": str(key),
            "http://127.0.0.1:8080": running.url,
        },
    )
    with nginx(tmp_path / "nginx", server):
        yield f"https://127.0.0.1:{port}", running.store, token, cert


@contextmanager
def nginx(prefix: Path, server: str) -> Iterator[None]:
    """Debian's nginx running ``server`` (a server block, with any upstream) from
    ``prefix``, until the block ends."""
    (prefix / "temp").mkdir(parents=True)
    temp = " ".join(
        f"{kind}_temp_path {prefix / 'temp' / kind};"
        for kind in ("client_body", "proxy", "fastcgi", "uwsgi", "scgi")
    )
    conf = prefix / "nginx.conf"
    conf.write_text(
        f"pid {prefix / 'nginx.pid'};\nerror_log {prefix / 'error.log'};\n"
        f"events {{ worker_connections 1024; }}\nhttp {{\n access_log off;\n {temp}\n{server}}}\n"
    )
    # the master binds its sockets before it leaves for the background: up once it returns
    started = subprocess.run([NGINX, "-p", str(prefix), "-c", str(conf)], capture_output=True)
    assert started.returncode == 0, started.stderr.decode()
    try:
        yield
    finally:
        subprocess.run(
            [NGINX, "-p", str(prefix), "-c", str(conf), "-s", "stop"], capture_output=True
        )


def test_a_command_through_nginx_is_audited_with_the_real_client_not_a_forged_one(
    proxy: tuple[str, Any, str, Path],
) -> None:
    url, store, token, cert = proxy
    sent = requests.post(
        f"{url}/api/v1/robots/hbs2/commands",
        json={"type": "say", "args": {"text": "hello through the proxy"}},
        headers={"Authorization": f"Bearer {token}", "X-Forwarded-For": "203.0.113.9"},
        verify=str(cert),
        timeout=10,
    )
    assert sent.status_code == 201, sent.text
    [send] = [e for e in store.directory.audit.since() if e.action == "send"]
    assert (send.actor, send.client) == ("ana", "127.0.0.1")  # nginx's $remote_addr


def test_the_live_stream_passes_through_nginx_at_once(proxy: tuple[str, Any, str, Path]) -> None:
    url, _, token, cert = proxy
    with requests.get(
        f"{url}/api/v1/events",
        headers={"Authorization": f"Bearer {token}"},
        verify=str(cert),
        stream=True,
        timeout=10,
    ) as stream:
        assert stream.status_code == 200
        assert stream.headers["content-type"].startswith("text/event-stream")
        first = next(line for line in stream.iter_lines(decode_unicode=True) if line)
    assert first == "event: robots"  # the first event, not held back in a buffer
