"""A tree's settings that profiles change (its params), in the editor: a therapist sees
each with the unit and range of where it is used and what each profile sets it to, changes
it as a field, and is asked before a number typed over a `${...}` takes the profile's
control away (Debian's chromium driven by Playwright)."""

from __future__ import annotations

from pathlib import Path

from playwright.sync_api import Dialog, Page, expect

from tests.editor.test_editor_page import node, open_tree


def test_the_hug_s_settings_show_what_each_profile_sets_and_a_change_is_saved_in_place(
    page: Page, editor: str, project: Path
) -> None:
    path = project / "trees" / "hug.yaml"
    before = path.read_text()
    open_tree(page, editor, "trees/hug.yaml")
    settings = page.locator("#params")
    expect(settings).to_be_visible()
    rest = page.get_by_label("hug rest s (needed)")
    expect(rest).to_have_value("10")
    # where it is used gives its unit and range; the profiles say what they set
    expect(page.locator("#param-hug_rest_s-help")).to_contain_text("used by Cooldown seconds")
    expect(page.locator("#param-hug_rest_s-help")).to_contain_text("s)")
    threshold_help = page.locator("#param-hug_threshold_n-help")
    expect(threshold_help).to_contain_text("profiles set it: adult: ")
    expect(threshold_help).to_contain_text("child: ")

    page.get_by_label("hug threshold n (needed)").fill("4.5")
    page.get_by_label("hug threshold n (needed)").press("Tab")
    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
    page.get_by_role("button", name="Save").click()
    expect(page.locator("#message")).to_have_text("saved trees/hug.yaml")
    assert path.read_text() == before.replace("hug_threshold_n: 3.0", "hug_threshold_n: 4.5")


def test_a_number_typed_over_a_setting_asks_first_and_keeps_it_unless_agreed(
    page: Page, editor: str, project: Path
) -> None:
    path = project / "trees" / "hug.yaml"
    before = path.read_text()
    open_tree(page, editor, "trees/hug.yaml")
    node(page, "root/0").click()  # Check: above ${hug_threshold_n}
    above = page.get_by_label("above")
    expect(above).to_have_value("${hug_threshold_n}")
    expect(page.locator("#node-above-help")).to_contain_text(
        "Set by the tree's setting hug_threshold_n (3 here; profiles: "
    )

    asked: list[str] = []

    def refuse(dialog: Dialog) -> None:
        asked.append(dialog.message)
        dialog.dismiss()

    page.once("dialog", refuse)
    above.fill("5")
    above.press("Tab")
    assert asked and "Replace ${hug_threshold_n} with 5?" in asked[0]
    expect(above).to_have_value("${hug_threshold_n}")  # kept: the profiles still decide
    expect(page.locator("#state")).to_have_text("saved")  # nothing changed

    page.once("dialog", lambda dialog: dialog.accept())
    above.fill("5")
    above.press("Tab")
    expect(page.locator("#state")).to_have_text("changed, not saved")
    page.get_by_role("button", name="Save").click()
    expect(page.locator("#message")).to_contain_text("saved trees/hug.yaml")
    after = path.read_text()
    assert 'above: "${hug_threshold_n}"}\n    - Check: {key: /sensors/force/right_n' in before
    assert "- Check: {key: /sensors/force/left_n, above: 5}" in after


def test_the_outline_says_each_leaf_in_words(page: Page, editor: str) -> None:
    open_tree(page, editor, "trees/hug.yaml")
    expect(node(page, "root/0")).to_contain_text(
        "force on the left side pad above hug_threshold_n N? (Check)"
    )
    expect(node(page, "root/2/child/1")).to_contain_text("say \u201chug_phrase\u201d (Say)")


def test_a_profile_that_does_not_load_is_named_beside_the_settings(
    page: Page, editor: str, project: Path
) -> None:
    # a broken profile is not silently missing: the settings say which file and where
    (project / "trees" / "profiles" / "broken.yaml").write_text("profile: broken\nparams: [1, 2\n")
    open_tree(page, editor, "trees/hug.yaml")
    problem = page.locator("#params .problem")
    expect(problem).to_contain_text("trees/profiles/broken.yaml:")
    expect(problem).to_contain_text("the editor leaves this profile out")
    expect(page.locator("#param-hug_threshold_n-help")).not_to_contain_text("broken")
