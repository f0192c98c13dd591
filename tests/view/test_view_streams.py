"""The live view's streams: a page connecting hears to fetch the state first, and a robot
watched by too many pages refuses more instead of slowing down."""

from __future__ import annotations

import socket
from collections.abc import Callable, Iterator

import pytest

from engine.clock import VirtualClock
from engine.view.hub import ViewHub
from engine.view.server import MAX_STREAMS, LiveSource, ViewServer


@pytest.fixture
def view() -> Iterator[ViewServer]:
    server = ViewServer(LiveSource(ViewHub(VirtualClock())), port=0)
    server.start()
    yield server
    server.stop()


@pytest.fixture
def open_stream(
    http_answer: Callable[..., str], view: ViewServer
) -> Callable[[int], tuple[socket.socket, str]]:
    """A page's stream on ``port``, and what came first on it (or the whole refusal)."""

    def opened(port: int) -> tuple[socket.socket, str]:
        page = socket.create_connection(("127.0.0.1", port), timeout=10)
        asked = f"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\nCookie: vest-{port}={view.token}"
        page.sendall(asked.encode() + b"\r\n\r\n")
        return page, http_answer(page, stream_until=b"resync")

    return opened


def test_a_page_hears_first_to_fetch_the_state_so_it_misses_nothing(
    view: ViewServer, open_stream: Callable[[int], tuple[socket.socket, str]]
) -> None:
    page, first = open_stream(view.port)
    with page:
        assert first.startswith("HTTP/1.1 200") and 'data: {"kind":"resync"}' in first


def test_a_robot_watched_by_too_many_pages_refuses_one_more(
    view: ViewServer, open_stream: Callable[[int], tuple[socket.socket, str]]
) -> None:
    pages = [open_stream(view.port) for _ in range(MAX_STREAMS)]
    try:
        assert all(first.startswith("HTTP/1.1 200") for _, first in pages)
        one_more, answer = open_stream(view.port)
        one_more.close()
        assert answer.startswith("HTTP/1.1 503") and "pages are watching" in answer
        pages.pop()[0].close()  # a page closes: another may come
        for _ in range(500):  # until the server heard the page leave (a few tries)
            again, answer = open_stream(view.port)
            if not answer.startswith("HTTP/1.1 503"):
                break
            again.close()
        pages.append((again, answer))
        assert answer.startswith("HTTP/1.1 200")
    finally:
        for page, _ in pages:
            page.close()
