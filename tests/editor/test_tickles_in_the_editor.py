"""The therapist guide's "That tickles!" behaviour, built in the editor as its section says,
click by click, without a line of YAML, and tried on the simulated vest with a pat: the
file saved is the tree the guide writes by hand, and `vest validate` accepts it."""

from __future__ import annotations

from pathlib import Path

from playwright.sync_api import Page, expect

from engine.cli import main
from engine.editor.tree_yaml import TreeText
from engine.nodes.registry import default_registry
from tests.editor.conftest import ROOT


def guide_s_tickles() -> str:
    guide = (ROOT / "docs" / "therapist-guide.md").read_text()
    return guide.split("# trees/tickles.yaml\n", 1)[1].split("```", 1)[0]


def without_ids(node: dict) -> dict:
    return {
        "type": node["type"],
        "name": node["name"],
        "args": node["args"],
        "children": [without_ids(child) for child in node["children"]],
    }


def add(page: Page, where: str, find: str, node_type: str) -> None:
    page.get_by_role("button", name=f"Add a node {where}").click()
    page.get_by_label("Find").fill(find)
    page.locator(f'#palette .palette-node[data-node="{node_type}"]').click()
    expect(page.locator("#node-form h3")).to_contain_text(node_type)


def fill(page: Page, label: str, value: str) -> None:
    page.get_by_label(label, exact=True).fill(value)
    page.get_by_label(label, exact=True).press("Tab")


def choose(page: Page, path: str) -> None:
    page.locator(f'#outline button[data-path="{path}"]').click()


def test_a_therapist_builds_that_tickles_in_the_editor_as_the_guide_says(
    page: Page, editor: str, project: Path, capsys
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_label("New tree (a name)").fill("tickles")
    page.get_by_role("button", name="Start a new tree").click()
    fill(page, "Looks how often (times a second)", "20")
    fill(page, "Wakes on (keys)", "/sensors/touch/pat")
    fill(page, "Priority", "42")
    fill(page, "What it does", 'A pat on a shoulder -> "That tickles!" with the left arm up.')

    add(page, "inside", "touch", "OnTouch")
    page.get_by_label("left_shoulder").first.check()
    page.get_by_label("right_shoulder").first.check()
    add(page, "after", "rest", "Cooldown")
    fill(page, "seconds (needed)", "5")
    page.get_by_label("counting from").select_option("start")
    add(page, "inside", "order", "Sequence")
    add(page, "inside", "same time", "Parallel")
    add(page, "inside", "say", "Say")
    fill(page, "text (needed)", "That tickles!")
    add(page, "after", "servo", "MoveServo")
    fill(page, "joint (needed)", "left_arm")
    fill(page, "angle deg (needed)", "45")
    fill(page, "speed dps", "60")
    choose(page, "root/1/child/0")  # the Parallel
    add(page, "after", "servo", "MoveServo")
    fill(page, "joint (needed)", "left_arm")
    fill(page, "angle deg (needed)", "0")
    fill(page, "speed dps", "60")

    expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
    page.get_by_label("Pad").select_option("left_shoulder")  # tried before it is saved
    page.get_by_role("button", name="Try it").click()
    expect(page.locator("#tried")).to_contain_text("left_shoulder touched", timeout=60_000)
    expect(page.locator("#tried")).to_contain_text('1.00 s tickles: says "That tickles!"')
    page.get_by_role("button", name="Save").click()
    expect(page.locator("#message")).to_have_text("saved trees/tickles.yaml")

    saved = project / "trees" / "tickles.yaml"
    registry = default_registry()
    made = TreeText(saved.read_text(), registry).outline()
    written = TreeText(guide_s_tickles(), registry).outline()
    assert without_ids(made["root"]) == without_ids(written["root"])
    assert made["settings"]["wake_on"] == ["/sensors/touch/pat"]
    assert made["settings"]["priority"] == 42
    assert main(["validate", str(project / "trees")]) == 0
    assert "ok:" in capsys.readouterr().out
