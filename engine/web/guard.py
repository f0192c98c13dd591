"""Who may ask a server of vest, and the headers every answer carries.

Every page and stream a vest process serves (the live view, the buttons, the editor,
Foxglove's live server) asks for its token, on loopback too, as Jupyter does: another
account on the same machine, or a web page open in the lab's browser, reaches loopback as
easily as the therapist does. The address vest prints carries the token
(``?token=...``); opening it sets a cookie (``HttpOnly``, ``SameSite=Strict``, named
after the port) and sends the browser on to the same address without the token, so it
is not left in the address bar or the history. A script may send it as ``Authorization:
Bearer TOKEN`` instead. Tokens are compared in constant time.

A request from a page of another site is refused whatever it carries: its ``Origin`` (sent
with every WebSocket, server-sent-events stream and POST) must be the server's own, or
one the server was told to trust (Foxglove's web app). On loopback only a page opened as
127.0.0.1 or localhost may ask at all (no other name can be made to point here: DNS
rebinding).
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
from collections.abc import Collection, Mapping

from starlette.datastructures import URL, Headers, QueryParams
from starlette.requests import cookie_parser
from starlette.responses import PlainTextResponse, RedirectResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")
PAGE_HEADERS = {
    # only the page's own files run: a drawing cannot carry a script or a javascript: link
    "Content-Security-Policy": "default-src 'self'; img-src 'self' data:; "
    "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'; base-uri 'none'",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
}
_WEB_SCHEME = {"ws": "http", "wss": "https"}
"""A WebSocket's page came from the web scheme of its own (its Origin says http)."""
NEEDS_TOKEN = "a token is needed: open the address vest printed (it ends in ?token=...)"
WRONG_TOKEN = (
    "this token is not this server's (an address from an earlier run?): open the address "
    "vest printed this time"
)
FOREIGN = "refused: a page of another site ({origin}) may not ask this server"


def new_token() -> str:
    """A fresh token for one server's run: 192 random bits, URL-safe."""
    return secrets.token_urlsafe(24)


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


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


class TokenGuard:
    """ASGI middleware for a server on ``host``: the rules above for every HTTP request
    and WebSocket. ``cookie`` names the cookie that keeps a browser in (one per port:
    browsers share cookies across a host's ports); ``origins`` are other sites' pages that
    may ask (with the token all the same)."""

    def __init__(
        self,
        app: ASGIApp,
        *,
        host: str,
        token: str,
        cookie: str,
        origins: Collection[str] = (),
    ) -> None:
        if not token:
            raise ValueError("a server of vest always has a token")
        self.app = app
        self.loopback = is_loopback(host)
        self.token = token.encode()
        self.cookie = cookie
        self.origins = frozenset(origin.rstrip("/") for origin in origins)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        refusal = self._refusal(scope, headers)
        if refusal is not None:
            if scope["type"] == "websocket":  # refused before it opens, in words where it can
                await refuse_websocket(scope, send, 403, refusal)
            else:
                await PlainTextResponse(refusal + "\n", status_code=403)(scope, receive, send)
            return
        query = QueryParams(scope["query_string"])
        if scope["type"] == "http" and "token" in query and _is_page_visit(scope, headers):
            await self._cookie_and_on(scope, query)(scope, receive, send)
            return
        await self.app(scope, receive, send)

    def _refusal(self, scope: Scope, headers: Headers) -> str | None:
        if self.loopback:
            host = headers.get("host", "")
            name, colon, port = host.rpartition(":") if not host.endswith("]") else ("", "", "")
            if not colon or not port.isdigit():  # no port given, or not one
                name = host
            if name not in LOOPBACK_NAMES:
                return "not this host: open the address vest printed"
        origin = headers.get("origin")
        own = f"{_WEB_SCHEME.get(scope['scheme'], scope['scheme'])}://{headers.get('host', '')}"
        if origin is not None and origin.rstrip("/") not in (own, *self.origins):
            return FOREIGN.format(origin=origin)
        if origin is None and headers.get("sec-fetch-site") == "cross-site":
            return FOREIGN.format(origin="another site")
        given = _tokens(scope, headers, self.cookie)
        if not any(hmac.compare_digest(token, self.token) for token in given):
            return WRONG_TOKEN if given else NEEDS_TOKEN
        return None

    def _cookie_and_on(self, scope: Scope, query: QueryParams) -> RedirectResponse:
        """The page's address without its token, with the cookie that keeps it in."""
        kept = [(name, value) for name, value in query.multi_items() if name != "token"]
        url = URL(scope=scope).replace(query=str(QueryParams(kept)) if kept else "")
        on = url.path + (f"?{url.query}" if url.query else "")
        answer = RedirectResponse(on, status_code=303)
        answer.set_cookie(
            self.cookie, self.token.decode(), httponly=True, samesite="strict", path="/"
        )
        return answer


async def refuse_websocket(scope: Scope, send: Send, status: int, why: str) -> None:
    """Refuses a WebSocket before it opens: with ``why`` as an HTTP answer where the server
    can send one (ASGI's denial response), else closed (the client sees 403)."""
    if "websocket.http.response" in scope.get("extensions", {}):
        start = {"type": "websocket.http.response.start", "status": status}
        start["headers"] = [(b"content-type", b"text/plain; charset=utf-8")]
        await send(start)
        body = (why + "\n").encode()
        await send({"type": "websocket.http.response.body", "body": body, "more_body": False})
        return
    await send({"type": "websocket.close", "code": 1008, "reason": why[:120]})


def _tokens(scope: Scope, headers: Headers, cookie: str) -> list[bytes]:
    """Every token a request carries: its bearer header, its cookie, its ``?token=``."""
    found: list[str] = []
    scheme, _, value = headers.get("authorization", "").partition(" ")
    if scheme.lower() == "bearer" and value:
        found.append(value.strip())
    jar = cookie_parser(headers.get("cookie", ""))  # others' odd cookies do not stop it
    if jar.get(cookie):
        found.append(jar[cookie])
    given = QueryParams(scope["query_string"]).get("token")
    if given:
        found.append(given)
    return [text.encode("utf-8", "replace") for text in found]


def _is_page_visit(scope: Scope, headers: Headers) -> bool:
    """A browser opening a page (a GET that takes HTML), not a script's request."""
    return scope.get("method") == "GET" and "text/html" in headers.get("accept", "")
