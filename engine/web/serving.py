"""Binding a server's socket, and running a server beside the robot in a thread.

Every server of vest listens on a socket made here: made as TCP (asyncio turns Nagle's
algorithm off only on sockets that say so; else each response's second write waits ~40 ms
for a delayed ACK), with the address named in one line when it cannot be had.
"""

from __future__ import annotations

import socket
import threading
from pathlib import Path

import uvicorn
from starlette.routing import Mount
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp

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
    host: str, port: int, *, shared: bool = False, listen: bool = True, named: str = ""
) -> socket.socket:
    """A TCP socket bound to ``host``:``port`` (0: any free port; ``shared``: other
    processes may bind it too). A ConfigError names the address when it cannot be had, as
    ``named`` (the options that chose it; default the address itself)."""
    try:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
        sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if shared:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.bind((host, port))
        if listen:
            sock.listen(2048)
        return sock
    except OSError as error:
        where = named or f"{host}:{port}"
        raise ConfigError(f"{where}: cannot listen there ({error.strerror or error})") from None


def address_of(host: str, port: int, path: str = "/") -> str:
    """How a browser reaches ``path`` on ``host``:``port`` (on every address, this
    machine's name)."""
    shown = socket.gethostname() if host in ("0.0.0.0", "::") else host
    shown = f"[{shown}]" if ":" in shown else shown
    return f"http://{shown}:{port}{path}"


class ServerThread:
    """``server`` (a uvicorn server of an app) serving on ``sock`` in a thread of its own,
    beside the robot. The socket listens before :meth:`start`: a page that asks early waits
    for its answer instead of being refused."""

    def __init__(self, server: uvicorn.Server, sock: socket.socket, name: str) -> None:
        self.server = server
        self.sock = sock
        self.port = int(sock.getsockname()[1])
        self._thread = threading.Thread(
            target=server.run, kwargs={"sockets": [sock]}, name=name, daemon=True
        )

    @classmethod
    def of(cls, app: ASGIApp, sock: socket.socket, name: str) -> ServerThread:
        config = uvicorn.Config(app, timeout_graceful_shutdown=GRACE_S, log_level="warning")
        return cls(uvicorn.Server(config), sock, name)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        """Ends the server (requests in flight get ``GRACE_S``) and frees its port."""
        self.server.should_exit = True
        if self._thread.is_alive():
            self._thread.join(timeout=GRACE_S + 5)
        self.sock.close()
