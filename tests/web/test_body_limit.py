"""A request body is refused when too big (declared or streamed) or when it stalls: a
client on a flaky link holds nothing for long, and a server stopping never waits on it."""

from __future__ import annotations

import socket
from collections.abc import Callable, Iterator

import pytest
from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.requests import Request
from starlette.responses import PlainTextResponse
from starlette.routing import Route

from engine.web.body_limit import BodyLimit
from engine.web.serving import ServerThread, listening_socket


async def echo(request: Request) -> PlainTextResponse:
    return PlainTextResponse(f"got {len(await request.body())} bytes")


@pytest.fixture
def port() -> Iterator[int]:
    limit = Middleware(BodyLimit, max_bytes=100, read_timeout_s=0.3)
    app = Starlette(routes=[Route("/", echo, methods=["POST"])], middleware=[limit])
    server = ServerThread(app, listening_socket("127.0.0.1", 0), "test")
    server.start()
    yield server.port
    server.stop()


Ask = Callable[[int, bytes], str]


@pytest.fixture
def ask(http_answer: Callable[..., str]) -> Ask:
    """Send ``request`` to ``port``; the whole answer."""

    def asked(port: int, request: bytes) -> str:
        with socket.create_connection(("127.0.0.1", port), timeout=10) as client:
            client.sendall(request)
            return http_answer(client)

    return asked


def test_a_body_within_the_limit_is_read(port: int, ask: Ask) -> None:
    answer = ask(port, b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello")
    assert answer.startswith("HTTP/1.1 200") and answer.endswith("got 5 bytes")


def test_a_body_that_stalls_is_refused_with_408(port: int, ask: Ask) -> None:
    answer = ask(port, b'POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 50\r\n\r\n{"but')
    assert answer.startswith("HTTP/1.1 408") and "did not come within 0.3 s" in answer


def test_a_streamed_body_over_the_limit_is_refused_with_413(port: int, ask: Ask) -> None:
    chunk = b"80\r\n" + b"x" * 128 + b"\r\n"
    request = b"POST / HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\n" + chunk
    assert ask(port, request).startswith("HTTP/1.1 413")
