"""Refusing request bodies over a limit with 413, declared or streamed, and stalled ones
with 408.

A body whose Content-Length is over the limit is refused before it is read; a chunked body
(no length) is counted as it arrives and refused as soon as it passes the limit, so a
client cannot make the service hold more than the limit in memory."""

from __future__ import annotations

import asyncio
from typing import Any

from starlette import status
from starlette.exceptions import HTTPException
from starlette.responses import JSONResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send


class BodyLimit:
    """ASGI middleware: 413 for bodies over ``max_bytes``; 408 for a body whose next part
    does not come within ``read_timeout_s`` (a client that stalls holds nothing for long,
    and a server stopping never waits on it)."""

    def __init__(self, app: ASGIApp, max_bytes: int, read_timeout_s: float = 10.0) -> None:
        self.app = app
        self.max_bytes = max_bytes
        self.read_timeout_s = read_timeout_s

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        length = dict(scope["headers"]).get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > self.max_bytes):
            await self._too_large()(scope, receive, send)
            return
        await self.app(scope, self._counting(receive), send)

    def _counting(self, receive: Receive) -> Receive:
        seen = 0
        whole = False  # once the body is in, receive waits for the client to leave: no limit

        async def counted() -> Message:
            nonlocal seen, whole
            if whole:
                return await receive()
            try:
                message = await asyncio.wait_for(receive(), self.read_timeout_s)
            except TimeoutError:
                why = f"the body did not come within {self.read_timeout_s:g} s"
                raise HTTPException(status.HTTP_408_REQUEST_TIMEOUT, why) from None
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                whole = not message.get("more_body", False)
                if seen > self.max_bytes:
                    raise HTTPException(status.HTTP_413_CONTENT_TOO_LARGE, self._detail())
            return message

        return counted

    def _too_large(self) -> Any:
        return JSONResponse({"detail": self._detail()}, status_code=413)

    def _detail(self) -> str:
        return f"the body is over {self.max_bytes} bytes"
