"""The tree editor in a real browser (Debian's chromium driven by Playwright): a therapist
opens a tree, adds a Say, saves, and the file is one `vest validate` accepts, with its
comments kept; a bad value is refused with the validator's message; everything works from
the keyboard; a file changed on disk meanwhile is never overwritten; axe-core finds
nothing serious."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from playwright.sync_api import Page, expect

from engine.cli import main

Problems = Callable[[Page], list[str]]


def open_tree(page: Page, editor: str, name: str) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_role("button", name=name).click()
    expect(page.locator("#editing")).to_be_visible()
    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")


def node(page: Page, path: str):
    return page.locator(f'#outline button[data-path="{path}"]')


def add(page: Page, where: str, node_type: str) -> None:
    page.get_by_role("button", name=f"Add a node {where}").click()
    page.locator(f'#palette .palette-node[data-node="{node_type}"]').click()


def validate(path: Path, capsys) -> str:
    code = main(["validate", str(path)])
    out = capsys.readouterr()
    assert code == 0, out.err
    return out.out


def test_a_say_added_under_a_sequence_is_saved_as_yaml_vest_validate_accepts(
    page: Page, editor: str, project: Path, capsys
) -> None:
    path = project / "trees" / "touch_thanks.yaml"
    before = path.read_text()
    open_tree(page, editor, "trees/touch_thanks.yaml")
    node(page, "root").click()
    add(page, "inside", "Say")
    page.get_by_label("text (needed)").fill("Thank you, that was nice")
    page.get_by_label("text (needed)").press("Tab")
    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
    page.get_by_role("button", name="Save").click()
    expect(page.locator("#message")).to_have_text("saved trees/touch_thanks.yaml")

    after = path.read_text()
    assert after == before + '    - Say: {text: "Thank you, that was nice"}\n'
    assert "wake_on: [/sensors/touch/pat]   # rests until a pat; answers at once" in after
    assert "ok: 1 file" in validate(path, capsys)
    expect(page.locator("#state")).to_have_text("saved")


def test_a_bad_value_is_refused_with_the_validator_s_message(
    page: Page, editor: str, project: Path
) -> None:
    path = project / "trees" / "hug.yaml"
    before = path.read_text()
    open_tree(page, editor, "trees/hug.yaml")
    node(page, "root/2/child/0").click()  # SetLed
    color = page.get_by_label("color (needed)", exact=True)
    page.once("dialog", lambda dialog: dialog.accept())  # yes, over the ${hug_color} setting
    color.fill("purplish")
    color.press("Enter")
    expect(page.locator("#problems")).to_contain_text("unknown color 'purplish'")
    expect(page.locator("#problems")).to_contain_text("did you mean 'purple'?")
    expect(node(page, "root/2/child/0")).to_contain_text("1 problem")
    expect(page.locator("#node-problems")).to_contain_text("unknown color 'purplish'")

    page.get_by_role("button", name="Save").click()  # asked first: the file has no problem
    expect(page.locator("#confirm")).to_be_visible()
    expect(page.locator("#confirm-text")).to_contain_text("would keep vest run from starting")
    page.get_by_role("button", name="Keep editing").click()
    assert path.read_text() == before

    page.get_by_role("button", name="Undo").click()  # back to pink
    expect(page.get_by_label("color (needed)", exact=True)).to_have_value("${hug_color}")
    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
    page.get_by_role("button", name="Redo").click()
    expect(page.get_by_label("color (needed)", exact=True)).to_have_value("purplish")


def test_a_file_changed_on_disk_while_open_is_noticed_and_not_overwritten(
    page: Page, editor: str, project: Path
) -> None:
    path = project / "trees" / "hug.yaml"
    open_tree(page, editor, "trees/hug.yaml")
    page.get_by_label("Priority").fill("52")
    page.get_by_label("Priority").press("Enter")
    by_hand = path.read_text().replace("rate_hz: 20", "rate_hz: 25")
    path.write_text(by_hand)
    page.get_by_role("button", name="Save").click()
    expect(page.locator("#message")).to_contain_text("changed on disk since it was opened")
    assert path.read_text() == by_hand


def test_the_keyboard_alone_builds_and_saves_a_new_tree(
    page: Page, editor: str, project: Path, capsys
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_label("New tree (a name)").focus()
    page.keyboard.type("shy")
    page.keyboard.press("Enter")  # the form's button
    expect(page.locator("#file-name")).to_have_text("trees/shy.yaml (new)")
    page.get_by_label("Wakes on (keys)").focus()
    page.keyboard.type("/sensors/touch/pat")
    page.keyboard.press("Tab")
    node(page, "root").focus()
    page.keyboard.press("Enter")
    page.get_by_role("button", name="Add a node inside").focus()
    page.keyboard.press("Enter")
    page.keyboard.type("touch")  # the palette's filter has the focus
    page.keyboard.press("Tab")
    page.keyboard.press("Enter")  # the first found: OnTouch
    expect(page.locator("#node-form h3")).to_have_text("OnTouch")
    page.get_by_role("button", name="Add a node after").focus()
    page.keyboard.press("Enter")
    page.keyboard.type("say")
    page.keyboard.press("Tab")
    page.keyboard.press("Tab")  # CarryOut mentions "say" first; then Say
    page.keyboard.press("Enter")
    page.get_by_label("text (needed)").focus()
    page.keyboard.type("Oh, hello")
    page.keyboard.press("Tab")
    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
    page.keyboard.press("Control+s")
    expect(page.locator("#message")).to_have_text("saved trees/shy.yaml")
    text = (project / "trees" / "shy.yaml").read_text()
    assert "wake_on: [/sensors/touch/pat]\n" in text
    assert '    - OnTouch: {}\n    - Say: {text: "Oh, hello"}\n' in text
    assert "ok: 1 file" in validate(project / "trees" / "shy.yaml", capsys)


def test_axe_finds_nothing_serious_in_the_editor(
    page: Page, editor: str, accessibility: Problems
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    assert accessibility(page) == []
    open_tree(page, editor, "trees/finger_game.yaml")
    node(page, "root/0").click()
    assert accessibility(page) == []
    page.get_by_role("button", name="Add a node after").click()
    assert accessibility(page) == []  # the palette


def test_the_palette_knows_the_robot_s_senses_by_their_words(page: Page, editor: str) -> None:
    # no node is called "squeeze": the palette says where a squeeze is, and which nodes ask
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_label("New tree (a name)").fill("squeezes")
    page.get_by_role("button", name="Start a new tree").click()
    page.get_by_role("button", name="Add a node inside").click()
    page.get_by_label("Find").fill("squeeze")
    expect(page.locator("#palette .palette-keys")).to_contain_text("/sensors/force/squeeze")
    expect(page.locator("#palette .palette-keys")).to_contain_text("/sensors/force/left_n")
    expect(page.locator('#palette .palette-node[data-node="OnEvent"]')).to_be_visible()
    expect(page.locator('#palette .palette-node[data-node="Say"]')).to_be_hidden()
    expect(page.locator('#palette .palette-node[data-node="CarryOut"]')).to_be_hidden()
