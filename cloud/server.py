"""Running the service: one process, or several sharing a port.

Stopping the service ends the operators' live streams and waiting long-polls at once
(they reconnect to the next service) instead of holding the shutdown up. Several workers
each bind the port with SO_REUSEPORT and the kernel spreads connections among them
(uvicorn's own --workers hands its workers a socket on which Nagle's algorithm stays on:
every request took ~45 ms more).
"""

from __future__ import annotations

import gc
import logging
import multiprocessing
import signal
import socket
import sys
from multiprocessing.connection import wait
from types import FrameType

import uvicorn
from fastapi import FastAPI

from cloud.services import CloudStore
from cloud.settings import Settings
from engine.errors import ConfigError

log = logging.getLogger(__name__)
GRACE_S = 3
"""How long requests in flight get to finish when the service stops."""


class CloudServer(uvicorn.Server):
    """A uvicorn server that tells the store it is closing before it waits for requests."""

    def __init__(self, config: uvicorn.Config, store: CloudStore) -> None:
        super().__init__(config)
        self.store = store

    async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
        self.store.begin_closing()
        await super().shutdown(sockets)


def server_for(app: FastAPI, **options: object) -> CloudServer:
    """A server for ``app`` (made by create_app); ``options`` go to uvicorn.Config."""
    config = uvicorn.Config(app, timeout_graceful_shutdown=GRACE_S, **options)  # type: ignore[arg-type]
    return CloudServer(config, app.state.store)


def tune_garbage_collector() -> None:
    """For a process that only serves: the objects made while starting are frozen out of
    the collector's scans, and young objects are collected less often. Telemetry makes
    many short-lived dicts; with the defaults, full collections paused the event loop for
    tens of milliseconds (bench_cloud's p99 with telemetry: ~100 ms before, ~65 ms after)."""
    gc.collect()
    gc.freeze()
    gc.set_threshold(20_000, 50, 1_000)


def listening_socket(host: str, port: int, *, shared: bool, listen: bool = True) -> socket.socket:
    """A TCP socket bound to ``host``:``port`` (``shared``: other workers may bind it too).
    A ConfigError names the address when it cannot be had (in use, not this machine's)."""
    try:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
        # IPPROTO_TCP named: asyncio turns Nagle off only on sockets that say they are TCP
        # (else each response's second write waits ~40 ms for a delayed ACK)
        sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if shared:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.bind((host, port))
        if listen:
            sock.listen(2048)
        return sock
    except OSError as error:
        raise ConfigError(
            f"--host {host} --port {port}: cannot listen there ({error.strerror or error})"
        ) from None


def serve(settings: Settings, host: str, port: int, *, shared: bool = False) -> None:
    """Run one service process until SIGTERM or Ctrl-C."""
    sock = listening_socket(host, port, shared=shared)
    from cloud.app import create_app

    if not shared:
        _say_where(host, port, 1)
    server = server_for(create_app(settings), log_level="info")
    tune_garbage_collector()
    server.run(sockets=[sock])


def serve_workers(settings: Settings, host: str, port: int, workers: int) -> None:
    """Run ``workers`` service processes on one port until SIGTERM or Ctrl-C; a worker that
    dies is started again."""
    listening_socket(host, port, shared=True, listen=False).close()  # named now if taken
    _say_where(host, port, workers)
    context = multiprocessing.get_context("spawn")
    stopping = False

    def start() -> multiprocessing.process.BaseProcess:
        process = context.Process(
            target=_worker, args=(settings.to_json(), host, port), name="vest-cloud-worker"
        )
        process.start()
        return process

    def stop(signum: int, _frame: FrameType | None) -> None:
        nonlocal stopping
        stopping = True
        for process in running:
            if process.pid is not None and process.is_alive():
                process.terminate()  # SIGTERM: each worker ends its requests and stops

    running = [start() for _ in range(workers)]
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    while running:
        wait([process.sentinel for process in running])
        for process in [p for p in running if not p.is_alive()]:
            running.remove(process)
            if not stopping:
                log.error("a worker ended (exit code %s); starting another", process.exitcode)
                running.append(start())


def _say_where(host: str, port: int, workers: int) -> None:
    shown = f"[{host}]" if ":" in host else host
    processes = "1 process" if workers == 1 else f"{workers} processes"
    print(f"vest cloud: operators open http://{shown}:{port}/ ({processes})", file=sys.stderr)


def _worker(settings_json: str, host: str, port: int) -> None:
    logging.basicConfig(level=logging.INFO, format="%(levelname)s:     %(message)s")
    serve(Settings.from_json(settings_json), host, port, shared=True)
