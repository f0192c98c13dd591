"""The robot's pages read at a glance by a therapist (issue 25, part 6): one legend; a
question answered no, and a tree waiting for one, are not drawn as failures; each status
has a word and a mark as well as a colour; wide drawings fit or scroll and the details stay
in sight; the keyboard alone chooses a node; a tablet shows it all; axe-core finds nothing
serious on the view (live and replay), the buttons page, the operator's page
(tests/cloud/test_operator_page.py) and the report."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from playwright.sync_api import Browser, Page, expect

from engine.cli import main
from tests.view.test_buttons_page import Session
from tests.view.test_view_page import node

ROOT = Path(__file__).resolve().parents[2]
Problems = Callable[[Page], list[str]]


def at_moment(page: Page, seconds: float) -> None:
    page.locator("#slider").evaluate(
        f"(slider) => {{ slider.value = '{seconds}'; slider.dispatchEvent(new Event('input')); }}"
    )
    expect(page.locator("#clock")).to_have_text(f"{seconds:.2f} s")


def test_a_tree_waiting_for_a_hug_reads_waiting_not_failed(page: Page, replay: str) -> None:
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    hug = page.locator('.tree[data-tree="hug"]')
    # nobody squeezes yet: the first question says no, so the tree waits; nothing failed
    expect(node(page, "hug", 1)).to_have_attribute("data-status", "FAILURE")
    expect(node(page, "hug", 1)).to_have_attribute("data-shown", "no")
    expect(node(page, "hug", 0)).to_have_attribute("data-shown", "waiting")
    expect(hug.locator("h2 .status")).to_have_text("waiting")
    expect(node(page, "hug", 1)).to_have_attribute(  # in words, as the live view says it
        "aria-label", "force on the left side pad above 3 N?: no"
    )
    assert page.locator('[data-shown="failed"]').count() == 0

    at_moment(page, 3.5)  # the squeeze: a yes, and the tree runs (a mark besides the colour)
    expect(node(page, "hug", 1)).to_have_attribute("data-shown", "yes")
    expect(node(page, "hug", 0)).to_have_attribute("data-shown", "running")
    expect(node(page, "hug", 0).locator(".mark")).to_have_text("\u25b6")
    expect(hug.locator("h2 .status")).to_have_text("running")


def test_one_legend_for_every_drawing_and_values_in_words(page: Page, replay: str) -> None:
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    expect(page.locator("#legend")).to_contain_text("waiting (a question: no)")
    assert page.locator("#legend").count() == 1
    assert page.locator(".tree svg").count() >= 6
    assert page.locator(".tree svg", has_text="legend").count() == 0  # none inside a drawing
    at_moment(page, 7.5)
    expect(page.locator('#keys tr[data-key="/sensors/force/squeeze"] td.value')).to_have_text(
        "right"
    )
    expect(page.locator('#keys tr[data-key="/sensors/range/left_mm"] td.value')).to_have_text(
        "nothing"
    )
    expect(page.locator('#keys tr[data-key="/sensors/touch/any"] td.value')).to_have_text("no")


def test_the_keyboard_alone_chooses_a_node_and_its_details_show(page: Page, replay: str) -> None:
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    for _ in range(80):  # Tab from the top of the page to the first node of a drawing
        page.keyboard.press("Tab")
        if page.evaluate("document.activeElement.dataset.node !== undefined"):
            break
    else:
        raise AssertionError("Tab never reached a node of a drawing")
    page.keyboard.press("Enter")
    expect(page.locator("#node")).to_be_visible()
    expect(page.locator("#node-facts")).to_contain_text("now")


def test_on_a_tablet_the_page_fits_and_a_wide_tree_fits_to_width(
    browser: Browser, replay: str, accessibility: Problems
) -> None:
    context = browser.new_context(viewport={"width": 768, "height": 1024}, has_touch=True)
    page = context.new_page()
    try:
        page.goto(replay)
        expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
        assert page.evaluate("document.documentElement.scrollWidth") <= 768
        game = page.locator('.tree[data-tree="finger_game"]')
        drawing = game.locator(".drawing")
        assert drawing.evaluate("(d) => d.scrollWidth > d.clientWidth")  # wide: it scrolls
        game.get_by_role("button", name="fit to width").click()
        expect(game.get_by_role("button", name="fit to width")).to_have_attribute(
            "aria-pressed", "true"
        )
        assert drawing.evaluate("(d) => d.scrollWidth <= d.clientWidth + 1")  # now it fits
        assert accessibility(page) == []
    finally:
        context.close()


def test_axe_finds_nothing_serious_on_the_replay_at_any_moment(
    page: Page, replay: str, accessibility: Problems
) -> None:
    page.goto(replay)
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    assert accessibility(page) == []
    at_moment(page, 7.5)
    node(page, "hug", 0).click()
    expect(page.locator("#node")).to_be_visible()
    assert accessibility(page) == []


def test_axe_finds_nothing_serious_on_the_buttons_page(
    page: Page, tmp_path: Path, accessibility: Problems
) -> None:
    session = Session(tmp_path)
    try:
        page.goto(session.address)
        expect(page.get_by_role("button").first).to_be_visible()
        assert accessibility(page) == []
    finally:
        session.stop()


def test_axe_finds_nothing_serious_in_a_session_s_report(
    page: Page, tmp_path: Path, monkeypatch, capsys, accessibility: Problems
) -> None:
    monkeypatch.chdir(ROOT)
    recorded = tmp_path / "demo.db"
    assert main(["run", "--fast", "--speech", "text", "--record", str(recorded)]) == 0
    assert main(["report", str(recorded)]) == 0
    capsys.readouterr()
    page.goto(recorded.with_suffix(".html").as_uri())
    assert accessibility(page) == []
