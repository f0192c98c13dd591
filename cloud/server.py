"""Running the service: one process, or several sharing a port.

Stopping a one-process service ends the operators' live streams and waiting long-polls at
once (they reconnect to the next service) instead of holding the shutdown up. Several
workers run under uvicorn's supervisor on one socket made here (uvicorn's own socket keeps
Nagle's algorithm on: every request took ~45 ms more).

``options`` are uvicorn's: ``ssl_certfile``/``ssl_keyfile`` to serve HTTPS on that socket
(checked first by :func:`engine.web.tls.tls_options`), ``forwarded_allow_ips``: the
addresses of proxies whose ``X-Forwarded-For``/``-Proto`` are believed (the audit log
then names the real client).
"""

from __future__ import annotations

import asyncio
import gc
import logging
import os
import signal
import socket
import sys
import threading
from types import FrameType

import uvicorn
from fastapi import FastAPI
from starlette.types import ASGIApp, Message, Receive, Scope, Send
from uvicorn.supervisors import Multiprocess

from cloud.services import CloudStore
from cloud.settings import Settings
from engine.web.serving import GRACE_S, listening_socket

log = logging.getLogger(__name__)


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


def serve(
    settings: Settings,
    host: str,
    port: int,
    *,
    shared: bool = False,
    options: dict[str, object] | None = None,
) -> None:
    """Run one service process until SIGTERM or Ctrl-C."""
    sock = listening_socket(host, port, shared=shared, named=f"--host {host} --port {port}")
    from cloud.app import create_app

    if not shared:
        _say_where(host, port, 1, "ssl_certfile" in (options or {}))
    server = server_for(create_app(settings), log_level="info", **(options or {}))
    tune_garbage_collector()
    server.run(sockets=[sock])


def serve_workers(
    settings: Settings,
    host: str,
    port: int,
    workers: int,
    options: dict[str, object] | None = None,
) -> None:
    """Run ``workers`` service processes on one port until SIGTERM or Ctrl-C.

    uvicorn's own supervisor (``Multiprocess``) starts them, checks they answer, and starts
    another when one dies; each worker reads its settings from the environment
    (:meth:`Settings.environment`) and serves on the socket made here (made as TCP, so
    Nagle's algorithm is off). Stopping ends the waiting long-polls and live streams at
    once, as one process does (:func:`app_from_environment`), and gives requests in flight
    ``GRACE_S`` to finish."""
    sock = listening_socket(host, port, shared=True, named=f"--host {host} --port {port}")
    os.environ.update(settings.environment())
    options = options or {}
    _say_where(host, port, workers, "ssl_certfile" in options)
    config = uvicorn.Config(
        "cloud.server:app_from_environment",
        factory=True,
        workers=workers,
        timeout_graceful_shutdown=GRACE_S,
        log_level="info",
        **options,  # type: ignore[arg-type]
    )
    Multiprocess(config, sockets=[sock]).run()


def app_from_environment() -> ASGIApp:
    """A worker's app: the settings its supervisor put in the environment. Once started,
    SIGTERM or SIGINT first tells its store the service is closing (long-polls answer 204,
    streams end), then reaches uvicorn's own handler, which stops the worker."""
    from cloud.app import create_app

    app = create_app(Settings())
    store: CloudStore = app.state.store
    tune_garbage_collector()

    async def closing_on_signals(scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "lifespan" or threading.current_thread() is not threading.main_thread():
            await app(scope, receive, send)
            return
        loop = asyncio.get_running_loop()

        async def send_then_listen(message: Message) -> None:
            await send(message)
            if message["type"] == "lifespan.startup.complete":  # uvicorn's handlers are in
                for signum in (signal.SIGTERM, signal.SIGINT):
                    _close_first(signum, loop, store)

        await app(scope, receive, send_then_listen)

    return closing_on_signals


def _close_first(signum: int, loop: asyncio.AbstractEventLoop, store: CloudStore) -> None:
    """On ``signum``, the store hears it is closing (on its loop), then the handler that
    was there."""
    then = signal.getsignal(signum)

    def handler(number: int, frame: FrameType | None) -> None:
        loop.call_soon_threadsafe(store.begin_closing)
        if callable(then):
            then(number, frame)

    signal.signal(signum, handler)


def _say_where(host: str, port: int, workers: int, tls: bool) -> None:
    shown = f"[{host}]" if ":" in host else host
    processes = "1 process" if workers == 1 else f"{workers} processes"
    scheme = "https" if tls else "http"
    print(f"vest cloud: operators open {scheme}://{shown}:{port}/ ({processes})", file=sys.stderr)
