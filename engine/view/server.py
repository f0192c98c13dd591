"""The view's web server: one page (engine/view/web/) for the live robot and for replays.

Plain HTTP from the standard library, a thread per connection, beside the robot:

- ``GET /`` the page, ``/view.js``, ``/view.css``;
- ``GET /api/info`` live or replay (with the recording's length and its moments);
- ``GET /api/snapshot[?at=S]`` every tree with its nodes' statuses, the blackboard, the
  recent actions and the statistics (now, or at S seconds into a recording);
- ``GET /api/svg/TREE/VERSION`` the tree drawn by Graphviz as ``vest render`` draws it,
  node ``n3`` being the fourth node depth-first;
- ``GET /api/node?tree=T&version=V&node=N`` a recorded node's status changes;
- ``GET /api/events`` (live) server-sent events, one JSON change each;
- with buttons (``vest run --buttons``): ``GET /buttons`` the therapist's page,
  ``GET /api/buttons`` the buttons and what shows, ``GET /api/buttons/events`` the shown
  set as it changes, ``POST /api/press`` ``{"button": N}`` presses one (JSON only, from the
  page's own origin: another site cannot press for the therapist).

On loopback (the default) no token is asked; on any other address every request must
carry ``?token=...`` (the address ``vest run --view`` prints has it).
"""

from __future__ import annotations

import contextlib
import hmac
import ipaddress
import json
import logging
import math
import queue
import re
import shutil
import socket
import subprocess
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, Protocol
from urllib.parse import parse_qs, unquote, urlparse

from engine.buttons.wizard import Wizard
from engine.errors import ConfigError, DeviceError
from engine.view.hub import Change, ViewHub

log = logging.getLogger(__name__)
WEB = Path(__file__).resolve().parent / "web"
STATIC = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/view.js": ("view.js", "text/javascript; charset=utf-8"),
    "/view.css": ("view.css", "text/css; charset=utf-8"),
    "/buttons": ("buttons.html", "text/html; charset=utf-8"),
    "/buttons.js": ("buttons.js", "text/javascript; charset=utf-8"),
    "/buttons.css": ("buttons.css", "text/css; charset=utf-8"),
}
MAX_PRESS_BYTES = 1024
POST_READ_TIMEOUT_S = 5.0
KEEPALIVE_S = 15.0
"""A stream with nothing to say writes a comment this often: a page that left is noticed."""
DOT_TIMEOUT_S = 20.0
CSP = "default-src 'self'; img-src 'self' data:; style-src 'self' 'unsafe-inline'"
"""Only the page's own files run: a drawing cannot carry a script or a javascript: link."""
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")


class ViewSource(Protocol):
    """What the page asks: the live hub (:class:`LiveSource`) or a recording."""

    def info(self) -> dict[str, Any]: ...

    def snapshot(self, at_s: float) -> Change: ...

    def dot(self, tree: str, version: int) -> str | None: ...

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]: ...


class LiveSource:
    """The running robot, through its :class:`ViewHub`."""

    def __init__(self, hub: ViewHub) -> None:
        self.hub = hub

    def info(self) -> dict[str, Any]:
        return {"mode": "live"}

    def snapshot(self, at_s: float) -> Change:
        return self.hub.snapshot()

    def dot(self, tree: str, version: int) -> str | None:
        return self.hub.dot(tree, version)

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]:
        return []  # the live page keeps each node's changes as they come


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class ViewServer:
    """Serves ``source`` (and the therapist's buttons, when given a ``wizard``) on
    ``host``:``port`` (0: any free port) in a thread of its own."""

    def __init__(
        self,
        source: ViewSource,
        *,
        host: str = "127.0.0.1",
        port: int = 8765,
        token: str | None,
        wizard: Wizard | None = None,
    ) -> None:
        if not is_loopback(host) and not token:
            raise ConfigError(f"the view on {host} needs a token (only loopback goes without)")
        self.source = source
        self.token = token
        self.wizard = wizard
        self._svg: dict[tuple[str, int], bytes] = {}
        self._svg_lock = threading.Lock()
        handler = _handler_for(self)
        try:
            self._server = ThreadingHTTPServer((host, port), handler)
        except OSError as error:
            raise DeviceError(
                error.errno,
                f"the view cannot listen on {host}:{port} ({error.strerror}); "
                "choose another with --view-port (0: any free one)",
            ) from None
        self._server.daemon_threads = True
        self.host, self.port = host, int(self._server.server_address[1])
        self._thread = threading.Thread(target=self._server.serve_forever, name="view", daemon=True)

    @property
    def url(self) -> str:
        """The page's address; on every address (0.0.0.0, ::), this machine's name."""
        return self.page_url("/")

    def page_url(self, page: str) -> str:
        """The address of ``page`` (``/``, ``/buttons``), with the token when one is needed."""
        host = socket.gethostname() if self.host in ("0.0.0.0", "::") else self.host
        shown = f"[{host}]" if ":" in host else host
        query = f"?token={self.token}" if self.token else ""
        return f"http://{shown}:{self.port}{page}{query}"

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        if isinstance(self.source, LiveSource):
            self.source.hub.close()
        if self.wizard is not None:
            self.wizard.close()
        self._server.shutdown()
        self._server.server_close()

    def host_allowed(self, host_header: str) -> bool:
        """On loopback, only a page opened as 127.0.0.1 or localhost may ask (a web page
        elsewhere cannot make the browser read the robot through a name of its own)."""
        if not is_loopback(self.host):
            return True  # the token guards it
        name = host_header.rsplit(":", 1)[0] if not host_header.endswith("]") else host_header
        return name in LOOPBACK_NAMES

    def svg(self, tree: str, version: int) -> bytes | None:
        """The tree drawn by Graphviz (cached); None when unknown or Graphviz is missing."""
        key = (tree, version)
        with self._svg_lock:
            if key in self._svg:
                return self._svg[key]
        source = self.source.dot(tree, version)
        dot = shutil.which("dot")
        if source is None or dot is None:
            return None
        try:
            done = subprocess.run(
                [dot, "-Tsvg"], input=source.encode(), capture_output=True, timeout=DOT_TIMEOUT_S
            )
        except (OSError, subprocess.TimeoutExpired) as error:
            log.error("drawing %s failed: %s", tree, error)
            return None
        if done.returncode != 0:
            return None
        with self._svg_lock:
            self._svg[key] = done.stdout
        return done.stdout


def _handler_for(view: ViewServer) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        server_version = "vest-view"

        def log_message(self, format: str, *args: Any) -> None:
            log.debug("view: " + format, *args)

        def _allowed(self, path: str, query: dict[str, str]) -> bool:
            """The Host header names this server, and the token is given when needed."""
            if not view.host_allowed(self.headers.get("Host", "")):
                self._send(403, b"not this host: open the address vest printed\n", "text/plain")
                return False
            given = query.get("token", "").encode("utf-8", "replace")
            if (
                view.token
                and path not in STATIC  # the page itself holds no data; it asks with the token
                and not hmac.compare_digest(given, view.token.encode())
            ):
                self._send(403, b"a token is needed: use the address vest printed\n", "text/plain")
                return False
            return True

        def do_GET(self) -> None:
            url = urlparse(self.path)
            query = {key: values[-1] for key, values in parse_qs(url.query).items()}
            if not self._allowed(url.path, query):
                return
            with contextlib.suppress(BrokenPipeError, ConnectionResetError):  # the page left
                self._route(url.path, query)

        def do_POST(self) -> None:
            with contextlib.suppress(BrokenPipeError, ConnectionResetError, TimeoutError):
                self._post()

        def _post(self) -> None:
            url = urlparse(self.path)
            query = {key: values[-1] for key, values in parse_qs(url.query).items()}
            if not self._allowed(url.path, query):
                return
            if url.path != "/api/press" or view.wizard is None:
                self._send(404, b"not found\n", "text/plain")
                return
            origin = self.headers.get("Origin")
            if origin is not None and urlparse(origin).netloc != self.headers.get("Host"):
                self._send(403, b"presses come from the buttons page only\n", "text/plain")
                return
            kind = self.headers.get("Content-Type", "").split(";")[0].strip()
            length = _count(self.headers.get("Content-Length", ""))
            if kind != "application/json" or length is None or length > MAX_PRESS_BYTES:
                self._send(400, b'send JSON: {"button": N}\n', "text/plain")
                return
            self.connection.settimeout(POST_READ_TIMEOUT_S)  # a body promised but not sent
            body = self.rfile.read(length)
            try:
                number = json.loads(body).get("button") if len(body) == length else None
            except (ValueError, AttributeError, RecursionError):
                number = None
            if isinstance(number, bool) or not isinstance(number, int):
                self._send(400, b'send JSON: {"button": N}\n', "text/plain")
                return
            if view.wizard.board.button(number) is None:
                self._send(404, b"no such button\n", "text/plain")
                return
            if number not in view.wizard.state()["shown"]:
                self._send(409, b"that button is not shown now\n", "text/plain")
                return
            button = view.wizard.press(number)
            assert button is not None
            self._send(202, json.dumps({"pressed": button.label}).encode(), "application/json")

        def _route(self, path: str, query: dict[str, str]) -> None:
            if path in STATIC:
                name, kind = STATIC[path]
                self._send(200, (WEB / name).read_bytes(), kind)
            elif path == "/api/info":
                self._json(view.source.info())
            elif path == "/api/snapshot":
                at = _number(query.get("at", "0"))
                if at is None:
                    self._send(400, b"at is a number of seconds\n", "text/plain")
                    return
                self._json(view.source.snapshot(at))
            elif path.startswith("/api/svg/"):
                self._svg(path.removeprefix("/api/svg/"))
            elif path == "/api/node":
                self._node(query)
            elif path == "/api/events" and isinstance(view.source, LiveSource):
                self._events(view.source.hub)
            elif path == "/api/buttons" and view.wizard is not None:
                board = view.wizard.board
                buttons = [button.to_json() for button in board.buttons]
                self._json({"buttons": buttons, "state": view.wizard.state()})
            elif path == "/api/buttons/events" and view.wizard is not None:
                with contextlib.suppress(BrokenPipeError, ConnectionResetError):
                    self._button_events(view.wizard)
            else:
                self._send(404, b"not found\n", "text/plain")

        def _svg(self, rest: str) -> None:
            tree, _, version = rest.rpartition("/")
            number = _count(version)
            drawn = view.svg(unquote(tree), number) if number is not None else None
            if drawn is None:
                self._send(404, b"no drawing of that tree (or no Graphviz)\n", "text/plain")
            else:
                self._send(200, drawn, "image/svg+xml")

        def _node(self, query: dict[str, str]) -> None:
            version, node = _count(query.get("version", "")), _count(query.get("node", ""))
            if version is None or node is None:
                self._send(400, b"version and node are numbers\n", "text/plain")
                return
            changes = view.source.node_changes(query.get("tree", ""), version, node)
            self._json([{"at": at, "status": s, "feedback": f} for at, s, f in changes])

        def _events(self, hub: ViewHub) -> None:
            page = hub.subscribe()
            try:
                self._stream_start()
                while True:
                    change = page.changes.get()
                    if change is None:
                        break
                    if page.overflowed and change.get("kind") != "end":  # behind: start over
                        page.overflowed = False
                        while not page.changes.empty():
                            page.changes.get_nowait()
                        change = {"kind": "resync"}
                    self.wfile.write(b"data: " + json.dumps(change).encode() + b"\n\n")
                    self.wfile.flush()
            finally:
                hub.unsubscribe(page)

        def _button_events(self, wizard: Wizard) -> None:
            page = wizard.subscribe()
            try:
                self._stream_start()
                while True:
                    try:
                        state = page.get(timeout=KEEPALIVE_S)
                    except queue.Empty:
                        self.wfile.write(b": still here\n\n")  # raises once the page left
                        self.wfile.flush()
                        continue
                    self.wfile.write(b"data: " + json.dumps(state).encode() + b"\n\n")
                    self.wfile.flush()
                    if state.get("ended"):
                        break
            finally:
                wizard.unsubscribe(page)

        def _stream_start(self) -> None:
            self.send_response(200)
            self.send_header("Content-Type", "text/event-stream")
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(b": connected\n\n")
            self.wfile.flush()

        def _json(self, value: Any) -> None:
            self._send(200, json.dumps(value).encode(), "application/json")

        def _send(self, status: int, body: bytes, kind: str) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.send_header("Content-Security-Policy", CSP)
            self.send_header("X-Content-Type-Options", "nosniff")
            self.end_headers()
            self.wfile.write(body)

    return Handler


def _number(text: str) -> float | None:
    """A finite number of seconds, or None."""
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _count(text: str) -> int | None:
    """A whole number as the page sends it (ASCII digits, at most 9), or None."""
    return int(text) if re.fullmatch(r"[0-9]{1,9}", text) else None
