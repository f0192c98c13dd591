"""Binding a server's socket, and running a server beside the robot in a thread.

Every server of vest listens on a socket made here: made as TCP (asyncio turns Nagle's
algorithm off only on sockets that say so; else each response's second write waits ~40 ms
for a delayed ACK), with the address named in one line when it cannot be had.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable
from pathlib import Path

import uvicorn
from starlette.routing import Mount
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from engine.errors import ConfigError

GRACE_S = 3
"""How long requests in flight get to finish when a server stops."""
SHARED = "/shared/"
"""Where every app serves the files all pages share (engine/web/static/: the stream client)."""


def shared_files() -> Mount:
    """The route of the files every page shares, at :data:`SHARED` (they hold no data)."""
    folder = Path(__file__).resolve().parent / "static"
    return Mount(SHARED.rstrip("/"), StaticFiles(directory=folder), name="shared")


def listening_socket(
    host: str, port: int, *, shared: bool = False, named: str = ""
) -> socket.socket:
    """A TCP socket bound to ``host``:``port`` (0: any free port; ``shared``: other
    processes may bind it too). A ConfigError names the address when it cannot be had, as
    ``named`` (the options that chose it; default the address itself)."""
    host = host.strip("[]")  # an IPv6 address as written in a URL: [::1]
    try:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
        sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if shared:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.bind((host, port))
        sock.listen(2048)
        return sock
    except OSError as error:
        where = named or f"{host}:{port}"
        raise ConfigError(f"{where}: cannot listen there ({error.strerror or error})") from None


def address_of(host: str, port: int, path: str = "/") -> str:
    """How a browser reaches ``path`` on ``host``:``port`` (on every address, this
    machine's name)."""
    shown = socket.gethostname() if host in ("0.0.0.0", "::") else host.strip("[]")
    shown = f"[{shown}]" if ":" in shown else shown
    return f"http://{shown}:{port}{path}"


class ServerThread:
    """``app`` served by uvicorn on ``sock`` in a thread of its own, beside the robot (or
    beside a test). ``make_server`` makes the uvicorn server of a config (a subclass that
    does more when it stops, say; default uvicorn's own).

    :meth:`start` returns once the server is up (its app started), so a page that connects
    right after hears everything from then on, and the server's start-up work is done
    before the robot's first tick instead of during it."""

    def __init__(
        self,
        app: ASGIApp,
        sock: socket.socket,
        name: str,
        make_server: Callable[[uvicorn.Config], uvicorn.Server] = uvicorn.Server,
    ) -> None:
        self.sock = sock
        self.port = int(sock.getsockname()[1])
        self._ready = threading.Event()
        config = uvicorn.Config(
            _noting_start(app, self._ready),
            timeout_graceful_shutdown=GRACE_S,
            log_level="warning",
            lifespan="on",
        )
        self.server = make_server(config)
        self._thread = threading.Thread(
            target=self.server.run, kwargs={"sockets": [sock]}, name=name, daemon=True
        )

    def start(self) -> None:
        """Serve; returns once serving (a ConfigError if the server could not start)."""
        self._thread.start()
        while not self._ready.wait(0.05):  # a server that failed to start ends its thread
            if not self._thread.is_alive():
                raise ConfigError(
                    f"the {self._thread.name} server on port {self.port} did not start"
                )

    def stop(self) -> None:
        """Ends the server (requests in flight get ``GRACE_S``) and frees its port."""
        self.server.should_exit = True
        if self._thread.is_alive():
            self._thread.join(timeout=GRACE_S + 5)
        self.sock.close()


def _noting_start(app: ASGIApp, ready: threading.Event) -> ASGIApp:
    """``app``, setting ``ready`` once uvicorn has started it (its lifespan's start-up)."""

    async def noted(scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "lifespan":
            await app(scope, receive, send)
            return

        async def send_noting(message: Message) -> None:
            await send(message)
            if message["type"] == "lifespan.startup.complete":
                ready.set()

        await app(scope, receive, send_noting)

    return noted
