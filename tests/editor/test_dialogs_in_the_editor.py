"""Dialogs in the editor: a question and its answer added without YAML, checked as typed,
heard as the robot hears it, saved with the rest of the file as it was."""

from __future__ import annotations

import copy
from pathlib import Path

from playwright.sync_api import Page, expect

from engine.editor.dialog_yaml import DialogText
from tests.editor.conftest import ROOT


def test_a_dialog_opened_and_saved_unchanged_is_byte_for_byte_the_same() -> None:
    text = (ROOT / "dialogs" / "default.yaml").read_text()
    dialog = DialogText(text)
    assert dialog.written(dialog.outline()) == text


def test_a_new_rule_is_written_as_the_others_and_a_follow_up_is_kept() -> None:
    text = (ROOT / "dialogs" / "default.yaml").read_text()
    dialog = DialogText(text)
    outline = copy.deepcopy(dialog.outline())
    pets = next(rule for rule in outline["rules"] if rule["rule"] == "pets")
    assert pets["more"]  # it asks back: the editor shows it and keeps that part
    pets["say"] = "I love animals! Have you got a pet?"
    outline["rules"].append({"rule": "dogs", "hear": ["do you like dogs"], "say": "I do!"})
    written = dialog.written(outline)
    assert (
        '  - id: dogs\n    hear: ["do you like dogs"]\n    say: "I do!"\n'
        'fallback: "Sorry, I did not understand."\nreprompt:' in written
    )
    assert (
        '    say: "I love animals! Have you got a pet?"\n'
        '    confirm: "Did you ask whether I like animals?"\n    then:\n      listen_s: 10\n'
        in written
    )


def test_a_therapist_adds_a_question_checks_it_is_heard_and_saves(
    page: Page, editor: str, project: Path
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_role("button", name="dialogs/default.yaml").click()
    expect(page.locator("#dialog-editing")).to_be_visible()
    page.get_by_role("button", name="Add a question and its answer").click()
    count = page.locator("fieldset.rule").count()
    page.locator(f"#rule-{count - 1}-rule").fill("football")
    page.get_by_label("A person says (one way of asking per line)").last.fill(
        "do you play football\nwhat about football"
    )
    page.get_by_label("The robot answers").last.fill("I cannot kick, but I love to watch!")
    page.get_by_label("The robot answers").last.press("Tab")
    expect(page.locator("#d-problems")).to_contain_text("vest validate accepts this dialog")

    page.get_by_role("button", name="Check how the robot hears the phrases").click()
    expect(page.locator("#heard")).to_contain_text("0 problem(s)", timeout=120_000)

    page.get_by_role("button", name="Save").last.click()
    expect(page.locator("#d-message")).to_have_text("saved dialogs/default.yaml")
    saved = (project / "dialogs" / "default.yaml").read_text()
    assert '  - id: football\n    hear: ["do you play football", "what about football"]\n' in saved


def test_a_phrase_another_question_has_is_a_problem_as_soon_as_it_is_typed(
    page: Page, editor: str
) -> None:
    page.goto(editor)
    expect(page.locator("body")).to_have_attribute("data-ready", "true")
    page.get_by_role("button", name="dialogs/default.yaml").click()
    page.get_by_role("button", name="Add a question and its answer").click()
    count = page.locator("fieldset.rule").count()
    page.locator(f"#rule-{count - 1}-rule").fill("me")
    page.get_by_label("A person says (one way of asking per line)").last.fill("what is your name")
    page.get_by_label("The robot answers").last.fill("Guess!")
    page.get_by_label("The robot answers").last.press("Tab")
    shared = "rules 'name' (line 14) and 'me' both listen for 'what is your name'"
    expect(page.locator("#d-problems")).to_contain_text(shared)
    page.get_by_role("button", name="Check how the robot hears the phrases").click()
    expect(page.locator("#heard")).to_contain_text(shared, timeout=120_000)
