"""Server-sent events, as every stream of vest sends them.

A stream starts with a comment (the page knows it is connected), sends each change as a
``data:`` line of JSON (``event:`` named where the page listens by name), and writes a
comment whenever it has had nothing to say for ``KEEPALIVE_S``, so a proxy does not close
an idle stream and a page that left is noticed.
"""

from __future__ import annotations

import json
from collections.abc import AsyncIterator
from typing import Any

from starlette.responses import StreamingResponse

KEEPALIVE_S = 15.0
CONNECTED = ": connected\n\n"
KEEPALIVE = ": still here\n\n"


def frame(data: Any, event: str | None = None) -> str:
    """One event: ``data`` as compact JSON, under ``event`` when named."""
    named = f"event: {event}\n" if event else ""
    return f"{named}data: {json.dumps(data, separators=(',', ':'))}\n\n"


def event_stream(frames: AsyncIterator[str]) -> StreamingResponse:
    """The response for a stream of ``frames`` (see :func:`frame`), never cached or
    buffered by a proxy. It ends when ``frames`` does, or is cancelled when the page
    leaves."""
    return StreamingResponse(
        frames,
        media_type="text/event-stream",
        headers={"Cache-Control": "no-store", "X-Accel-Buffering": "no"},
    )
