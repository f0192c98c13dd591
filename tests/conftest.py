"""The one browser every page test uses: Debian's chromium driven by Playwright
(``playwright install`` downloads a browser and is not used), for the robot's pages and
the cloud's alike."""

from __future__ import annotations

import shutil
import socket
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import parse_qs, urlsplit

import pytest

from engine.privacy.site_data import SiteKey, site_key

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page

CHROMIUM_FLAGS = [
    "--no-sandbox",  # the tests may run as root
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",  # this machine has no network to phone home to
    "--disable-component-update",
    "--disable-sync",
]


@pytest.fixture(autouse=True)
def site_data(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Every test's site keeps its data (key, index, consent, audit) in a folder of its
    own (VEST_DATA), never in the user's: what one test records no other reads."""
    folder = tmp_path_factory.mktemp("site") / "data"
    monkeypatch.setenv("VEST_DATA", str(folder))
    return folder


@pytest.fixture
def the_site_key(site_data: Path) -> SiteKey:
    """The key of the test's site (made now when the test has not made it yet)."""
    return site_key(site_data, create=True)


@pytest.fixture
def consenting(site_data: Path) -> Callable[..., None]:
    """Writes a consent record: ``consenting("kid-17", "sensors", "speech_text")``."""

    def write(person: str, *covers: str) -> None:
        site_data.mkdir(mode=0o700, parents=True, exist_ok=True)
        with open(site_data / "consent.yaml", "a", encoding="utf-8") as file:
            file.write(
                f"{person}:\n  given_by: guardian\n  given_on: 2026-01-05\n"
                f"  covers: [{', '.join(covers)}]\n"
            )

    return write


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    from playwright.sync_api import sync_playwright

    chromium = shutil.which("chromium")
    assert chromium, "Debian's chromium is missing: run scripts/setup (apt chromium)"
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=chromium, args=CHROMIUM_FLAGS)
        yield launched
        launched.close()


@pytest.fixture
def page(browser: Browser) -> Iterator[Page]:
    """A fresh page the size of a laptop's window; a script error on it fails the test."""
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    opened = context.new_page()
    errors: list[str] = []
    opened.on("pageerror", lambda error: errors.append(str(error)))
    yield opened
    context.close()
    assert errors == [], f"the page threw: {errors}"


def read_answer(client: socket.socket, stream_until: bytes = b"") -> str:
    """An HTTP answer read from ``client`` as it comes, in however many packets: its head
    and the body its Content-Length names; a stream (200 with no length) until it holds
    ``stream_until``."""
    answer = b""
    while True:
        head, blank, body = answer.partition(b"\r\n\r\n")
        if blank:
            length = _content_length(head)
            if length is not None and len(body) >= length:
                break
            if length is None and stream_until in body:
                break
        part = client.recv(4096)
        if not part:
            break
        answer += part
    return answer.decode()


def _content_length(head: bytes) -> int | None:
    for line in head.split(b"\r\n")[1:]:
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"content-length":
            return int(value)
    return None


def with_token(url: str, path: str) -> str:
    """The address of ``path`` on the server vest printed as ``url``, carrying its token
    (as a script sends it; a browser that opened ``url`` carries it in a cookie)."""
    parts = urlsplit(url)
    token = parse_qs(parts.query)["token"][0]
    joined = "&" if "?" in path else "?"
    return f"{parts.scheme}://{parts.netloc}{path}{joined}token={token}"


@pytest.fixture
def at() -> Callable[[str, str], str]:
    """:func:`with_token`, for tests that ask a page's server as a script does."""
    return with_token


@pytest.fixture
def http_answer() -> Callable[..., str]:
    """:func:`read_answer`, for tests that speak HTTP on a raw socket."""
    return read_answer


def serious_accessibility_problems(page: Page) -> list[str]:
    """What axe-core (the engine of the browsers' own accessibility tools) finds serious or
    critical on ``page`` as it is now: one line per rule, with the elements it names."""
    from axe_playwright_python.sync_playwright import Axe

    found = Axe().run(page).response["violations"]
    return [
        f"{rule['id']} ({rule['impact']}): {rule['help']}: "
        + ", ".join(str(node["target"]) for node in rule["nodes"][:5])
        for rule in found
        if rule["impact"] in ("serious", "critical")
    ]


@pytest.fixture
def accessibility() -> Callable[[Page], list[str]]:
    """:func:`serious_accessibility_problems`, for the page tests."""
    return serious_accessibility_problems
