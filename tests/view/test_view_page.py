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

from engine.errors import ConfigError
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
    drawn = {card.get_attribute("data-tree") for card in page.locator(".tree").all()}
    assert drawn >= DEMO_TREES
    # the squeeze at 3 s: the hug's first question is answered yes (a mark and a word too)
    expect(node(page, "hug", 1)).to_have_attribute("data-shown", "yes", timeout=30_000)
    expect(page.locator('#keys tr[data-key="/sensors/force/left_n"] td.value')).not_to_have_text(
        "0.0", timeout=30_000
    )
    node(page, "hug", 1).click()
    expect(page.locator("#node-facts")).to_contain_text("Check key=/sensors/force/left_n above=3.0")
    expect(page.locator("#node-changes li").first).to_contain_text("answered yes")
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
    expect(press).to_contain_text("therapist: presses the button 'Well done'")


def test_a_view_on_another_address_needs_its_token(page: Page) -> None:
    """A token is asked on any address but loopback; a guarded page refuses a request without it."""
    with pytest.raises(ConfigError, match=r"the view on 0\.0\.0\.0 needs a token"):
        ViewServer(EmptySource(), host="0.0.0.0", port=0, token=None)
    guarded = ViewServer(EmptySource(), port=0, token="s3cret")
    guarded.start()
    base = guarded.url.removesuffix("?token=s3cret")
    try:
        for path in ("api/snapshot", "api/info", "api/events", "api/svg/hug/1"):
            refused = page.goto(base + path)
            assert refused is not None and refused.status == 403, path
            wrong = page.goto(base + path + "?token=%C3%A9")  # not ASCII: refused, not a crash
            assert wrong is not None and wrong.status == 403, path
        page.goto(guarded.url)  # the page itself loads, and asks with the token
        expect(page.locator("body")).to_have_attribute("data-ready", "true")
        expect(page.locator("#mode")).to_contain_text("replay of -")
    finally:
        guarded.stop()


def test_odd_requests_are_answered_not_crashed_on(page: Page, replay: str) -> None:
    base = replay.rstrip("/")
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


def test_on_loopback_only_a_page_opened_as_loopback_may_ask(replay: str) -> None:
    import requests

    snapshot = replay.rstrip("/") + "/api/snapshot"
    assert requests.get(snapshot, timeout=10).status_code == 200
    rebound = requests.get(snapshot, headers={"Host": "attacker.example:80"}, timeout=10)
    assert rebound.status_code == 403
