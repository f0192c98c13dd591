"""The view in a real browser (Debian's chromium driven by Playwright): live, every tree of
the demo drawn and a node turning green when the hug happens; in a replay, the slider
shows the state at a moment."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Page, expect

from engine.view.server import ViewServer

ROOT = Path(__file__).resolve().parents[2]
VEST = "import sys; from engine.cli import main; sys.exit(main())"
DEMO_TREES = {"dialog", "finger_game", "hug", "iot_command", "touch_thanks", "tracking"}


@pytest.fixture
def live_demo() -> Iterator[str]:
    """`vest run --view` on the demo, in real time; its page's address."""
    process = subprocess.Popen(
        [sys.executable, "-c", VEST, "run", "--speech", "text", "--view", "--view-port", "0"],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert process.stderr is not None
    address = ""
    for line in process.stderr:
        if line.startswith("view: "):
            address = line.removeprefix("view: ").strip()
            break
    try:
        assert address.startswith("http://127.0.0.1:"), "vest run --view printed no address"
        yield address
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=30)


def node(page: Page, tree: str, index: int):
    return page.locator(f'.tree[data-tree="{tree}"] [data-node="{index}"]')


def test_the_live_page_draws_every_tree_and_the_hug_lights_up(
    page: Page, live_demo: str, accessibility: Callable[[Page], list[str]]
) -> None:
    page.goto(live_demo)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    assert accessibility(page) == []  # axe-core: nothing serious on the live page
    for tree in sorted(DEMO_TREES):  # a page open before the session began gets them as
        expect(page.locator(f'.tree[data-tree="{tree}"]')).to_have_count(1)  # they start
    # the squeeze at 3 s: the hug's first question is answered yes (a mark and a word too)
    expect(node(page, "hug", 1)).to_have_attribute("data-shown", "yes", timeout=30_000)
    expect(page.locator('#keys tr[data-key="/sensors/force/left_n"] td.value')).not_to_have_text(
        "0.0", timeout=30_000
    )
    node(page, "hug", 1).click()
    expect(page.locator("#node-facts")).to_contain_text("Check key=/sensors/force/left_n above=3.0")
    # its changes, newest first: on a loaded machine the squeeze may be over by now
    expect(page.locator("#node-changes")).to_contain_text("answered yes")
    expect(page.locator('#devices tr[data-key="touch"]')).to_contain_text("online")


def test_the_replay_slider_shows_the_robot_at_a_moment(page: Page, replay: str) -> None:
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    expect(page.locator("#mode")).to_contain_text("replay of demo.db")
    expect(node(page, "hug", 0)).to_have_attribute("data-status", "FAILURE")

    page.locator("#slider").evaluate(
        "(slider) => { slider.value = '3.5'; slider.dispatchEvent(new Event('input')); }"
    )
    expect(page.locator("#clock")).to_have_text("3.50 s")
    expect(node(page, "hug", 0)).to_have_attribute("data-status", "RUNNING")
    expect(node(page, "hug", 1)).to_have_attribute("data-status", "SUCCESS")
    expect(page.locator("#actions")).to_contain_text("I love hugs!")

    page.locator("#next-action").click()  # the next thing the robot did: the wave's greeting
    expect(page.locator("#actions li:not(.tone-world)").first).to_contain_text("wave_greeting")

    page.locator("#back").click()
    page.locator("#back").click()
    clock = float(page.locator("#clock").inner_text().split()[0])
    assert clock < 6.0

    # what happened reads as the terminal's timeline: sentences, each saying what it is
    page.locator("#slider").evaluate(
        "(slider) => { slider.value = '7.5'; slider.dispatchEvent(new Event('input')); }"
    )
    press = page.locator("#actions li[data-tone=therapist]").first
    expect(press).to_contain_text("scenario: presses the button 'Well done'")  # scripted


def test_the_page_opens_on_what_happened_with_the_engineering_tables_folded(
    page: Page, replay: str
) -> None:
    page.set_viewport_size({"width": 800, "height": 900})  # a tablet: one column
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    happened = page.get_by_role("heading", name="what happened")
    expect(happened).to_be_in_viewport()  # above the trees, not 1,270 px down
    expect(page.locator("#keys")).to_be_hidden()  # folded: for engineers
    page.get_by_text("for engineers: the blackboard, the devices, the ticks").click()
    expect(page.locator("#keys")).to_be_visible()


def test_the_page_shows_where_the_camera_sees_a_hand_held_up(page: Page, replay: str) -> None:
    """The demo's finger game: a hand held up at arm's length at 22 s; its box drawn in the
    camera's frame, and said in words (the picture itself never reaches the page)."""
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    expect(page.locator("#camera-said")).to_have_text("no hand held up")
    page.locator("#slider").evaluate(
        "(slider) => { slider.value = '22.6'; slider.dispatchEvent(new Event('input')); }"
    )
    expect(page.locator("#camera-said")).to_contain_text("a hand held up at")
    expect(page.locator("#camera-said")).to_contain_text("5 fingers")
    expect(page.locator("#camera-frame rect.hand")).to_have_count(1)


def test_every_request_needs_the_view_s_token_on_loopback_too(page: Page) -> None:
    """Another account on the machine reaches loopback as easily as the therapist: the
    page, its data and its streams all ask for the token the printed address carries; the
    browser that opened it is kept in by a cookie, and the token leaves the address bar."""
    guarded = ViewServer(EmptySource(), port=0, token="s3cret-" + "x" * 25)
    guarded.start()
    base = guarded.url.split("?")[0]
    try:
        for path in ("", "view.js", "api/snapshot", "api/info", "api/events", "api/svg/hug/1"):
            refused = page.goto(base + path)
            assert refused is not None and refused.status == 403, path
            assert "open the address vest printed" in refused.text(), path
            wrong = page.goto(base + path + "?token=%C3%A9")  # not ASCII: refused, not a crash
            assert wrong is not None and wrong.status == 403, path
        page.goto(guarded.url)
        expect(page.locator("body")).to_have_attribute("data-ready", "true")
        expect(page.locator("#mode")).to_contain_text("replay of -")
        assert page.url == base  # the token is no longer in the address bar nor the history
        cookie = next(c for c in page.context.cookies() if c["name"] == f"vest-{guarded.port}")
        assert cookie["httpOnly"] and cookie["sameSite"] == "Strict"
        answered = page.goto(base + "api/info")  # the cookie carries it from now on
        assert answered is not None and answered.status == 200
    finally:
        guarded.stop()


def test_another_site_s_page_cannot_read_or_press(
    replay: str, at: Callable[[str, str], str]
) -> None:
    import requests

    for path in ("/api/snapshot", "/api/events", "/api/press"):
        evil = requests.post if path == "/api/press" else requests.get
        answer = evil(at(replay, path), headers={"Origin": "https://evil.example"}, timeout=10)
        assert answer.status_code == 403 and "another site" in answer.text, path
    cross = requests.get(at(replay, "/api/snapshot"), headers={"Sec-Fetch-Site": "cross-site"})
    assert cross.status_code == 403


def test_odd_requests_are_answered_not_crashed_on(page: Page, replay: str) -> None:
    page.goto(replay)  # kept in by its cookie
    base = replay.split("?")[0].rstrip("/")
    for path, status in [
        ("/api/snapshot?at=nan", 400),
        ("/api/snapshot?at=1e999", 400),
        ("/api/node?tree=hug&version=%C2%B2&node=1", 400),
        ("/api/node?tree=hug&version=1&node=99999999999999999999", 400),
        ("/api/svg/../../etc/passwd", 404),
        ("/api/svg/hug/abc", 404),
        ("/nothing", 404),
    ]:
        answered = page.goto(base + path)
        assert answered is not None and answered.status == status, path


class EmptySource:
    """A view source with nothing to show."""

    def info(self) -> dict:
        return {"mode": "replay", "file": "-", "duration": 0.0, "moments": [], "actions": []}

    def snapshot(self, at_s: float) -> dict:
        return {"now": 0.0, "trees": [], "keys": [], "actions": [], "stats": None}

    def dot(self, tree: str, version: int) -> None:
        return None

    def node_changes(self, tree: str, version: int, node: int) -> list:
        return []


def test_a_tree_name_cannot_smuggle_a_link_into_its_drawing() -> None:
    from engine.loader.tree_drawing import escape

    assert escape('hello" { /*') == 'hello\\" { /*'
    assert escape("two\nlines") == "two\\nlines"


def test_on_loopback_only_a_page_opened_as_loopback_may_ask(
    replay: str, at: Callable[[str, str], str]
) -> None:
    import requests

    snapshot = at(replay, "/api/snapshot")
    assert requests.get(snapshot, timeout=10).status_code == 200
    rebound = requests.get(snapshot, headers={"Host": "attacker.example:80"}, timeout=10)
    assert rebound.status_code == 403
