"""A tree tried from the editor on the simulated vest, as in a session: the event as
strong, as long and as many times as asked, the tree among the folder's other trees (so
priorities and waits show), the timeline in sentences, and a word when the tree did
nothing; an event that cannot be is refused in words."""

from __future__ import annotations

from pathlib import Path

import pytest
from playwright.sync_api import Page, expect

from engine.cli.edit_tries import TryError, TryOnSimulatedVest, tried_events
from tests.editor.conftest import CONFIG, ROOT

PADS = [name for device in CONFIG.devices.values() for name in device.pad_names]


def test_a_squeeze_tried_on_the_hug_as_it_is_on_the_page(project: Path) -> None:
    try_out = TryOnSimulatedVest(project, ROOT / "examples/robots/sim.yaml", PADS)
    text = (project / "trees" / "hug.yaml").read_text().replace("I love hugs!", "Squish!")
    timeline = try_out("trees/hug.yaml", text, {"kind": "squeeze"})
    assert "1.00 s world: squeezed left 6 N, right 6 N for 2 s" in timeline
    assert '1.00 s hug: says "Squish!"' in timeline
    assert "I love hugs!" in (project / "trees" / "hug.yaml").read_text()  # the file unchanged


def test_a_squeeze_on_one_side_presses_that_side_pad_alone() -> None:
    [left] = tried_events({"kind": "squeeze", "side": "left", "strength_n": 2.5}, PADS)
    assert left["squeeze"] == {"left_n": 2.5, "right_n": 0.0, "seconds": 2.0}
    [right] = tried_events({"kind": "squeeze", "side": "right"}, PADS)
    assert right["squeeze"] == {"left_n": 0.0, "right_n": 6.0, "seconds": 2.0}


def test_a_try_with_a_profile_sets_the_trees_as_that_profile_does(project: Path) -> None:
    # the hug's threshold is the profile's: 2 N for a child; a 2.5 N squeeze is a hug then
    try_out = TryOnSimulatedVest(project, ROOT / "examples/robots/sim.yaml", PADS)
    text = (project / "trees" / "hug.yaml").read_text()
    asked = {"kind": "squeeze", "strength_n": 2.5}
    assert any(
        "hug: says" in line
        for line in try_out("trees/hug.yaml", text, {**asked, "profile": "child"})
    )
    assert not any("hug: says" in line for line in try_out("trees/hug.yaml", text, asked))
    with pytest.raises(TryError, match=r"no profile 'grandma' \(profiles: adult, child"):
        try_out("trees/hug.yaml", text, {**asked, "profile": "grandma"})


def test_repeated_squeezes_are_apart_by_default_so_each_is_a_squeeze_of_its_own() -> None:
    first, second = tried_events({"kind": "squeeze", "times": 2}, PADS)
    assert (first["at"], second["at"]) == (1.0, 4.0)  # 2 s each, a second between


def test_two_squeezes_tried_among_the_other_trees_show_who_speaks_and_who_gives_way(
    project: Path,
) -> None:
    try_out = TryOnSimulatedVest(project, ROOT / "examples/robots/sim.yaml", PADS)
    text = (
        (project / "trees" / "hug.yaml").read_text().replace("hug_rest_s: 10.0", "hug_rest_s: 1.0")
    )
    asked = {"kind": "squeeze", "strength_n": 4, "seconds": 1, "times": 2, "apart_s": 3}
    timeline = try_out("trees/hug.yaml", text, asked)
    assert "1.00 s world: squeezed left 4 N, right 4 N for 1 s" in timeline
    assert "4.00 s world: squeezed left 4 N, right 4 N for 1 s" in timeline
    said = [line.split(" s ")[0] for line in timeline if line.endswith('hug: says "I love hugs!"')]
    assert said[0] == "1.00" and said[1].startswith("4.0") and len(said) == 2  # once each


def test_a_pat_among_the_folder_s_trees_is_answered_by_the_tree_that_has_the_turn(
    project: Path,
) -> None:
    # tried alone, the hug would say nothing of a pat; among the others, touch_thanks does
    try_out = TryOnSimulatedVest(project, ROOT / "examples/robots/sim.yaml", PADS)
    text = (project / "trees" / "hug.yaml").read_text()
    timeline = try_out("trees/hug.yaml", text, {"kind": "pat", "pad": "middle_back"})
    assert '1.00 s touch_thanks: says "Thank you"' in timeline
    assert timeline[-1].startswith("hug did nothing: what it waits for did not happen")
    assert timeline[-1].endswith(
        "; its settings in this try: hug_threshold_n 3.0, volume 0.8, hug_rest_s 10.0"
    )


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
        ({"kind": "squeeze", "strength_n": 500}, "strength_n: 500 is not from 0.5 to 50"),
        ({"kind": "wave", "times": 6}, "times: 6 is not from 1 to 5"),
        ({"kind": "wave", "times": 1.5}, "times: a whole number from 1 to 5"),
        ({"kind": "pat", "pad": "middle_back", "apart_s": "soon"}, "apart_s: a number"),
        ({"kind": "squeeze", "seconds": True}, "seconds: a number from 0.1 to 10"),
        ({"kind": "wave", "times": 10**400}, "times: 10000000000000000000 is not from 1"),
        ({"kind": "squeeze", "side": "middle"}, "side: 'middle' is not one of both, left, right"),
        (
            {"kind": "squeeze", "times": 2, "apart_s": 1.5},
            "1.5 s apart, each lasting 2 s, they would be one long squeeze",
        ),
    ],
)
def test_an_event_that_cannot_be_is_refused_in_words(asked: object, why: str) -> None:
    with pytest.raises(TryError, match=why):
        tried_events(asked, PADS)


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


def test_the_page_tries_two_squeezes_says_what_it_tried_and_forgets_it_for_another_tree(
    page: Page, editor: str
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_role("button", name="trees/hug.yaml").click()
    # the priority says what it means among the folder's trees
    help_text = page.locator("#setting-priority-help")
    expect(help_text).to_contain_text("Other trees: iot_command 60, dialog 48")
    expect(help_text).to_contain_text("At 19 or lower this tree never interrupts another one")

    page.get_by_label("What happens").select_option("squeeze")
    page.get_by_label("Strength (N)").fill("4")
    page.get_by_label("How many times").fill("2")
    page.get_by_label("Apart (s)").fill("3")
    page.get_by_role("button", name="Try it").click()
    expect(page.locator("#tried-what")).to_have_text(
        "Tried on trees/hug.yaml, among the folder's other trees: "
        "2 times: a squeeze of 4 N on both sides, 3 s apart, with the trees' own settings"
    )
    expect(page.locator("#tried")).to_contain_text(
        "4.00 s world: squeezed left 4 N, right 4 N for 2 s", timeout=60_000
    )
    page.get_by_role("button", name="trees/touch_thanks.yaml").click()
    expect(page.locator("#tried")).to_be_empty()  # a try belongs to the tree it was made on
    expect(page.locator("#tried-what")).to_have_text("")
