"""The editor is safe to leave open: saves sent at once never lose one silently, nothing
outside the folder is read (nor quoted) by its checks and tries, and a save that would keep
`vest run` from starting says why first."""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from pathlib import Path

import pytest
import requests

from engine.cli import main
from engine.dialogs.library import OUTSIDE
from engine.editor.workspace import EditRefused, Workspace

Address = Callable[[str, str], str]
CONSENT = "kid-17:\n  given_by: guardian\n  given_on: 2026-11-20\n  covers: [sensors]\n"


def test_saves_sent_at_once_from_one_version_write_one_and_refuse_the_others(
    editor: str, at: Address, project: Path
) -> None:
    opened = requests.get(at(editor, "/api/file?name=trees/hug.yaml"), timeout=30).json()
    outline, version = opened["outline"], opened["version"]
    answers: list[requests.Response] = []
    start = threading.Barrier(4)

    def save(number: int) -> None:
        changed = {**outline, "settings": {**outline["settings"], "priority": 50 + number}}
        body = {"file": "trees/hug.yaml", "outline": changed, "version": version}
        start.wait()
        answers.append(requests.post(at(editor, "/api/save"), json=body, timeout=60))

    savers = [threading.Thread(target=save, args=(number,)) for number in range(1, 5)]
    for saver in savers:
        saver.start()
    for saver in savers:
        saver.join()
    assert sorted(answer.status_code for answer in answers) == [200, 409, 409, 409]
    refused = [answer.json()["message"] for answer in answers if answer.status_code == 409]
    assert all("changed on disk since it was opened" in why for why in refused)
    won = next(answer for answer in answers if answer.status_code == 200).json()["version"]
    assert (
        requests.get(at(editor, "/api/file?name=trees/hug.yaml"), timeout=30).json()["version"]
        == won
    )  # what is on disk is the save that was answered 200


def test_a_subtree_outside_the_folder_is_never_read_nor_quoted(
    workspace: Workspace, editor: str, at: Address, site_data: Path
) -> None:
    site_data.mkdir(parents=True, exist_ok=True)
    consent = site_data / "consent.yaml"
    consent.write_text(CONSENT)
    for written in (str(consent), "../../site/consent.yaml"):
        text = f"name: peek\nrate_hz: 5\nroot:\n  Sequence:\n    - Subtree: {{file: {written}}}\n"
        problems = workspace.check("trees/peek.yaml", text)
        assert any(problem["message"] == OUTSIDE for problem in problems), problems
        assert not any("kid-17" in problem["text"] for problem in problems)
        tried = requests.post(
            at(editor, "/api/try"),
            json={
                "file": "trees/peek.yaml",
                "outline": _outline_of(workspace, text),
                "version": None,
                "event": {"kind": "squeeze"},
            },
            timeout=60,
        )
        assert tried.status_code == 400 and OUTSIDE in tried.json()["message"]
        assert "kid-17" not in tried.text


def test_a_tree_named_as_another_is_refused_unless_saved_anyway(workspace: Workspace) -> None:
    text, _ = workspace.read("trees/hug.yaml")
    problems = workspace.check("trees/hug_copy.yaml", text)
    assert [p["message"] for p in problems if p["here"]] == [
        "two trees are named 'hug' (also " + str(workspace.folder / "trees" / "hug.yaml") + ")"
    ]
    with pytest.raises(EditRefused, match="the change has 1 problem") as refused:
        workspace.save("trees/hug_copy.yaml", text, None)
    assert refused.value.status == 409
    assert not (workspace.folder / "trees" / "hug_copy.yaml").exists()
    workspace.save("trees/hug_copy.yaml", text, None, over_problems=True)  # "Save anyway"
    assert (workspace.folder / "trees" / "hug_copy.yaml").exists()


def test_a_tree_saved_into_the_dialogs_is_refused(
    workspace: Workspace, capsys: pytest.CaptureFixture[str]
) -> None:
    text, _ = workspace.read("trees/hug.yaml")
    problems = workspace.check("dialogs/hug.yaml", text)
    assert [p["message"] for p in problems] == [
        "a tree in dialogs/: vest run reads every file there as a dialog"
    ]
    with pytest.raises(EditRefused) as refused:
        workspace.save("dialogs/hug.yaml", text, None)
    assert refused.value.status == 409
    dialog, _ = workspace.read("dialogs/default.yaml")
    assert workspace.check("trees/default.yaml", dialog)[0]["message"] == (
        "a dialog in trees/: vest run reads every file there as a tree"
    )
    (workspace.folder / "dialogs" / "hug.yaml").write_text(text)  # by hand: validate says so
    assert main(["validate", str(workspace.folder / "dialogs")]) == 1
    assert "a tree in dialogs/" in capsys.readouterr().err


def _outline_of(workspace: Workspace, text: str) -> dict[str, object]:
    from engine.editor.tree_yaml import TreeText

    outline = TreeText(text, workspace.registry).outline()
    assert outline is not None
    return outline


def test_a_link_among_the_dialogs_to_a_file_outside_is_never_read_nor_quoted(
    workspace: Workspace, editor: str, at: Address, site_data: Path, tmp_path: Path
) -> None:
    site_data.mkdir(parents=True, exist_ok=True)
    (site_data / "consent.yaml").write_text(CONSENT)
    (workspace.folder / "dialogs" / "consent.yaml").symlink_to(site_data / "consent.yaml")
    secret = tmp_path / "secret.yaml"
    secret.write_text(
        'dialog: secret\nrules:\n  - hear: ["hello"]\n    say: "OUTSIDE my brother hits me"\n'
    )
    (workspace.folder / "dialogs" / "secret.yaml").symlink_to(secret)
    text = (
        "name: talk\nrate_hz: 10\nwake_on: [/speech/heard]\nroot:\n  Sequence:\n"
        "    - OnEvent: {key: /speech/heard, save_as: /vars/talk}\n"
        "    - Reply: {heard: /vars/talk, dialog: secret}\n"
    )
    problems = workspace.check("trees/talk.yaml", text)
    told = json.dumps(problems)
    assert "kid-17" not in told and "OUTSIDE" not in told and "brother" not in told
    assert any(problem["message"] == OUTSIDE for problem in problems)
    tried = requests.post(
        at(editor, "/api/try"),
        json={
            "file": "trees/talk.yaml",
            "outline": _outline_of(workspace, text),
            "version": None,
            "event": {"kind": "say", "text": "hello"},
        },
        timeout=60,
    )
    assert tried.status_code == 400 and "brother" not in tried.text and "kid-17" not in tried.text


def test_a_save_is_not_blamed_for_problems_another_file_had_before(
    workspace: Workspace,
) -> None:
    """A new user's find: with a broken dialog in the folder, a good tree's save was
    refused for the dialog's problems."""
    (workspace.folder / "dialogs" / "broken.yaml").write_text("dialog: broken\nrules: 3\n")
    text, _ = workspace.read("trees/dialog.yaml")
    new = text.replace("name: dialog", "name: answers")
    assert any(not problem["here"] for problem in workspace.check("trees/answers.yaml", new))
    workspace.save("trees/answers.yaml", new, None)  # a new tree, fine in itself
    assert (workspace.folder / "trees" / "answers.yaml").read_text() == new
