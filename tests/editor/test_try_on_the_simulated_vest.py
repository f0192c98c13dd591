"""A tree tried from the editor on the simulated vest: one event, the timeline in
sentences; an event that cannot be is refused in words."""

from __future__ import annotations

from pathlib import Path

import pytest
from playwright.sync_api import Page, expect

from engine.cli.edit_tries import TryError, TryOnSimulatedVest, tried_event
from tests.editor.conftest import CONFIG, ROOT

PADS = [name for device in CONFIG.devices.values() for name in device.pad_names]


def test_a_squeeze_tried_on_the_hug_as_it_is_on_the_page(project: Path) -> None:
    try_out = TryOnSimulatedVest(project, ROOT / "examples/robots/sim.yaml", PADS)
    text = (project / "trees" / "hug.yaml").read_text().replace("I love hugs!", "Squish!")
    timeline = try_out("trees/hug.yaml", text, {"kind": "squeeze"})
    assert "1.00 s world: squeezed left 6 N, right 6 N for 2 s" in timeline
    assert '1.00 s hug: says "Squish!"' in timeline
    assert "I love hugs!" in (project / "trees" / "hug.yaml").read_text()  # the file unchanged


def test_words_said_reach_a_dialog_tree(project: Path) -> None:
    try_out = TryOnSimulatedVest(project, ROOT / "examples/robots/sim.yaml", PADS)
    text = (project / "trees" / "dialog.yaml").read_text()
    timeline = try_out("trees/dialog.yaml", text, {"kind": "say", "text": "what is your name"})
    assert any(line.startswith("1.00 s dialog: says") for line in timeline), timeline


@pytest.mark.parametrize(
    "asked, why",
    [
        ({"kind": "pat", "pad": "elbow"}, "no pad 'elbow' on this robot"),
        ({"kind": "say", "text": ""}, "the words a person says"),
        ({"kind": "say", "text": "x" * 201}, "1 to 200 characters"),
        ({"kind": "dance"}, "a pat, a squeeze"),
        ("pat", "a pat, a squeeze"),
    ],
)
def test_an_event_that_cannot_be_is_refused_in_words(asked: object, why: str) -> None:
    with pytest.raises(TryError, match=why):
        tried_event(asked, PADS)


def test_a_tree_watched_live_is_the_live_view_of_it_running(page: Page, editor: str) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_role("button", name="trees/hug.yaml").click()
    page.get_by_label("What happens").select_option("squeeze")
    page.get_by_role("button", name="Watch it live").click()
    link = page.get_by_role("link", name="Open the live view")
    expect(link).to_be_visible(timeout=60_000)
    page.goto(link.get_attribute("href") or "")
    expect(page.locator("body")).to_have_attribute("data-ready", "true", timeout=30_000)
    assert page.locator('.tree[data-tree="hug"]').count() == 1
    expect(page.locator("#actions")).to_contain_text("I love hugs!", timeout=30_000)
