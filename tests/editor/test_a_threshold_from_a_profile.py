"""A therapist builds "squeezed twice within 4 seconds" whose threshold each profile sets,
without writing YAML: a new setting, what the child and adult profiles set it to, and a
try of two light squeezes on the left pad as the child's session would be (Debian's
chromium driven by Playwright)."""

from __future__ import annotations

from pathlib import Path

from playwright.sync_api import Page, expect

from tests.editor.test_editor_page import add, node


def test_a_new_setting_its_profiles_and_a_try_as_the_child_s_session(
    page: Page, editor: str, project: Path
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_label("New tree (a name)").fill("two_squeezes")
    page.get_by_label("New tree (a name)").press("Enter")
    node(page, "root").click()
    add(page, "inside", "TimesWithin")
    page.get_by_label("times (needed)").fill("2")
    page.get_by_label("within s (needed)").fill("4")
    page.get_by_label("within s (needed)").press("Tab")
    add(page, "inside", "Check")
    page.get_by_label("key (needed)").fill("/sensors/force/left_n")
    page.get_by_label("above").fill("${left_squeeze_n}")
    page.get_by_label("above").press("Tab")
    expect(page.locator("#problems")).to_contain_text("unknown parameter ${left_squeeze_n}")

    # the settings offer the name the node used; its value here, then each profile's
    expect(page.get_by_label("New setting")).to_have_value("left_squeeze_n")
    page.get_by_label("its value here").fill("3")
    page.get_by_role("button", name="Add the setting").click()
    expect(page.get_by_label("left squeeze n (needed)")).to_have_value("3")
    page.get_by_label("child profile").fill("2")
    page.get_by_label("child profile").press("Tab")
    # the tree is not saved: a profile setting what no saved tree declares would stop the
    # robot, so the profiles' values wait for Save
    expect(page.locator("#message")).to_contain_text(
        "The child profile will set left_squeeze_n to 2 when you save the tree"
    )
    page.get_by_label("adult profile").fill("4")
    page.get_by_label("adult profile").press("Tab")
    expect(page.locator("#params")).to_contain_text(
        "profiles set it: adult: 4 (when you save), child: 2 (when you save)"
    )
    assert "left_squeeze_n" not in (project / "trees" / "profiles" / "child.yaml").read_text()

    node(page, "root/0").click()  # the Sequence's first child: the counting
    add(page, "after", "Say")
    page.get_by_label("text (needed)").fill("Two squeezes!")
    page.get_by_label("text (needed)").press("Tab")
    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
    page.get_by_role("button", name="Save", exact=True).click()
    expect(page.locator("#message")).to_have_text(
        "saved trees/two_squeezes.yaml, and the profiles' values (2)"
    )
    child = (project / "trees" / "profiles" / "child.yaml").read_text()
    assert "left_squeeze_n: 2\n" in child and "hug_threshold_n: 2.0" in child  # in place
    assert "left_squeeze_n: 4\n" in (project / "trees" / "profiles" / "adult.yaml").read_text()

    # two light squeezes of the left pad: nothing with the tree's own 3 N, the child's 2 N
    # makes it answer
    page.get_by_label("What happens").select_option("squeeze")
    page.get_by_label("Side").select_option("left")
    page.get_by_label("Strength (N)").fill("2.5")
    page.get_by_label("How many times").fill("2")
    page.get_by_role("button", name="Try it").click()
    expect(page.locator("#tried")).to_contain_text("two_squeezes did nothing", timeout=60_000)
    expect(page.locator("#tried")).to_contain_text("its settings in this try: left_squeeze_n 3")
    page.get_by_label("Settings").select_option("child")
    page.get_by_role("button", name="Try it").click()
    expect(page.locator("#tried-what")).to_contain_text(
        "a squeeze of 2.5 N on the left side pad, 3 s apart, with the child profile's settings"
    )
    expect(page.locator("#tried")).to_contain_text(
        'two_squeezes: says "Two squeezes!"', timeout=60_000
    )
    expect(page.locator("#tried")).to_contain_text(
        "two_squeezes answered; its settings in this try: left_squeeze_n 2 (profile child)"
    )
