"""Who may ask a server of vest, and the headers every answer carries.

On loopback (the default) only a page opened as 127.0.0.1 or localhost may ask: a web
page elsewhere cannot make the browser read the robot through a name of its own (DNS
rebinding). On any other address every request but the page's own files must carry
``?token=...`` (compared in constant time); the address vest prints carries it.
"""

from __future__ import annotations

import hmac
import ipaddress
from collections.abc import Collection, Mapping

from starlette.datastructures import URL, Headers, QueryParams
from starlette.responses import PlainTextResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from engine.errors import ConfigError

LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")
PAGE_HEADERS = {
    # only the page's own files run: a drawing cannot carry a script or a javascript: link
    "Content-Security-Policy": "default-src 'self'; img-src 'self' data:; "
    "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'; base-uri 'none'",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
}


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def check_listening(host: str, token: str | None, what: str) -> None:
    """A ConfigError when ``what`` would listen beyond loopback without a token."""
    if not is_loopback(host) and not token:
        raise ConfigError(f"{what} on {host} needs a token (only loopback goes without)")


class SecurityHeaders:
    """ASGI middleware: ``headers`` (default :data:`PAGE_HEADERS`) on every answer, which
    is also never cached unless it says otherwise."""

    def __init__(self, app: ASGIApp, headers: Mapping[str, str] = PAGE_HEADERS) -> None:
        self.app = app
        self.headers = [(name.lower().encode(), value.encode()) for name, value in headers.items()]

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                given = {name for name, _ in message["headers"]}
                extra = [(name, value) for name, value in self.headers if name not in given]
                if b"cache-control" not in given:
                    extra.append((b"cache-control", b"no-store"))
                message["headers"] = [*message["headers"], *extra]
            await send(message)

        await self.app(scope, receive, with_headers)


class LoopbackOrToken:
    """ASGI middleware for a server on ``host``: the rule above. ``open_paths`` need no
    token (the page's files, which hold no data and ask with the token), nor does anything
    under ``open_folders`` (each ending in ``/``)."""

    def __init__(
        self,
        app: ASGIApp,
        *,
        host: str,
        token: str | None,
        open_paths: Collection[str] = (),
        open_folders: Collection[str] = (),
    ) -> None:
        check_listening(host, token, "a page")
        self.app = app
        self.loopback = is_loopback(host)
        self.token = token
        self.open_paths = frozenset(open_paths)
        self.open_folders = tuple(open_folders)
        if any(not folder.endswith("/") or folder == "/" for folder in self.open_folders):
            raise ValueError(f"open folders end in '/' and are not the root: {open_folders}")

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http":
            refusal = self._refusal(scope)
            if refusal is not None:
                await PlainTextResponse(refusal + "\n", status_code=403)(scope, receive, send)
                return
        await self.app(scope, receive, send)

    def _under_open_folder(self, path: str) -> bool:
        return bool(self.open_folders) and path.startswith(self.open_folders)

    def _refusal(self, scope: Scope) -> str | None:
        if self.loopback:
            host = Headers(scope=scope).get("host", "")
            name, colon, port = host.rpartition(":") if not host.endswith("]") else ("", "", "")
            if not colon or not port.isdigit():  # no port given, or not one
                name = host
            if name not in LOOPBACK_NAMES:
                return "not this host: open the address vest printed"
        path = URL(scope=scope).path
        if self.token is None or path in self.open_paths or self._under_open_folder(path):
            return None
        given = QueryParams(scope["query_string"]).get("token", "")
        if not hmac.compare_digest(given.encode("utf-8", "replace"), self.token.encode()):
            return "a token is needed: use the address vest printed"
        return None
