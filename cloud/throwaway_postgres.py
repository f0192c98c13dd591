"""A throwaway PostgreSQL cluster, for the tests and the benchmarks: Debian's server
binaries, initdb in a temporary folder, pg_ctl on a free loopback port, stopped and removed
afterwards. As root the cluster runs as the ``postgres`` user (the server refuses to run as
root); otherwise as whoever runs it. Trust authentication, loopback only, fsync off: for
throwaway data, never for a robot's."""

from __future__ import annotations

import glob
import os
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

import psycopg


def server_binaries() -> Path:
    """The folder with initdb and pg_ctl: Debian keeps them out of PATH."""
    try:
        folder = subprocess.run(
            ["pg_config", "--bindir"], capture_output=True, text=True, check=True
        ).stdout.strip()
        if (Path(folder) / "initdb").exists():
            return Path(folder)
    except (OSError, subprocess.CalledProcessError):
        pass
    found = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"))
    if not found:
        raise RuntimeError("no PostgreSQL server here: run scripts/setup (apt postgresql)")
    return Path(found[-1]).parent


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


class PostgresCluster:
    """``start()`` gives the server's URL; ``new_database()`` a fresh empty database."""

    def __init__(self) -> None:
        self.binaries = server_binaries()
        self.folder = Path(tempfile.mkdtemp(prefix="vest-pg-"))
        self.data = self.folder / "data"
        self.port = free_port()
        self._databases = 0
        self._as_postgres = os.geteuid() == 0

    @property
    def url(self) -> str:
        return f"postgresql://vest@127.0.0.1:{self.port}/postgres"

    def start(self) -> str:
        if self._as_postgres:
            shutil.chown(self.folder, "postgres")
        self._run("initdb", "-D", str(self.data), "-U", "vest", "-A", "trust", "-E", "UTF8")
        self._run(
            "pg_ctl",
            "-D",
            str(self.data),
            "-l",
            str(self.folder / "server.log"),
            "-w",
            "-o",
            f"-p {self.port} -k {self.folder} -c listen_addresses=127.0.0.1 -c fsync=off"
            " -c max_connections=300",
            "start",
        )
        return self.url

    def new_database(self) -> str:
        """A new empty database's URL (each test gets its own)."""
        self._databases += 1
        name = f"test_{self._databases}"
        with psycopg.connect(self.url, autocommit=True) as db:
            db.execute(f"CREATE DATABASE {name}")
        return self.url.rsplit("/", 1)[0] + f"/{name}"

    def stop(self) -> None:
        try:
            self._run("pg_ctl", "-D", str(self.data), "-m", "immediate", "stop")
        finally:
            shutil.rmtree(self.folder, ignore_errors=True)

    def _run(self, program: str, *args: str) -> None:
        line = [str(self.binaries / program), *args]
        if self._as_postgres:
            line = ["runuser", "-u", "postgres", "--", *line]
        done = subprocess.run(line, capture_output=True, text=True, cwd=self.folder)
        if done.returncode != 0:
            raise RuntimeError(f"{program} failed ({done.returncode}): {done.stderr.strip()}")
