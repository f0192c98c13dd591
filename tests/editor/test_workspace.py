"""The editor's folder: it reads and writes there only, never over a change made on disk
meanwhile, and never a tree with problems over one without them unless asked."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from engine.cli.run_inputs import robot_catalogue
from engine.editor.workspace import EditRefused, Workspace
from engine.loader.tree_file import TreeLoader
from tests.editor.conftest import CONFIG


@pytest.mark.parametrize("name", ["../outside.yaml", "/etc/passwd.yaml", "trees/../../x.yaml"])
def test_the_editor_never_writes_outside_its_folder(workspace: Workspace, name: str) -> None:
    with pytest.raises(EditRefused) as refused:
        workspace.save(name, "name: x\n", None)
    assert refused.value.status in (400, 403)
    assert not (workspace.folder.parent / "outside.yaml").exists()


def test_a_link_leading_out_of_the_folder_is_neither_read_nor_written(
    workspace: Workspace, tmp_path: Path
) -> None:
    secret = tmp_path / "secret.yaml"
    secret.write_text("password: hunter2\n")
    os.symlink(secret, workspace.folder / "trees" / "link.yaml")
    with pytest.raises(EditRefused, match="outside the folder"):
        workspace.read("trees/link.yaml")
    with pytest.raises(EditRefused, match="outside the folder"):
        workspace.save("trees/link.yaml", "name: x\n", None)
    assert secret.read_text() == "password: hunter2\n"
    assert "trees/link.yaml" not in [each["file"] for each in workspace.files()]


def test_only_yaml_files_are_edited(workspace: Workspace) -> None:
    with pytest.raises(EditRefused, match=r"\.yaml files only"):
        workspace.save("trees/run.sh", "rm -rf /\n", None)


def test_the_folder_s_trees_subtrees_profiles_and_dialogs_are_listed(workspace: Workspace) -> None:
    listed = {each["file"]: each["kind"] for each in workspace.files()}
    assert listed["trees/hug.yaml"] == "tree"
    assert listed["trees/parts/greet.yaml"] == "subtree"
    assert listed["trees/profiles/child.yaml"] == "profile"
    assert listed["dialogs/default.yaml"] == "dialog"


def test_a_file_changed_on_disk_meanwhile_is_never_overwritten(workspace: Workspace) -> None:
    text, version = workspace.read("trees/hug.yaml")
    path = workspace.folder / "trees" / "hug.yaml"
    path.write_text(text.replace("priority: 50", "priority: 55"))  # someone, by hand
    with pytest.raises(EditRefused, match="changed on disk since it was opened") as refused:
        workspace.save("trees/hug.yaml", text.replace("rate_hz: 20", "rate_hz: 10"), version)
    assert refused.value.status == 409
    assert "priority: 55" in path.read_text() and "rate_hz: 20" in path.read_text()


def test_a_new_file_is_not_written_over_one_that_exists(workspace: Workspace) -> None:
    with pytest.raises(EditRefused, match="there is a file of that name already: open it"):
        workspace.save("trees/hug.yaml", "name: hug\n", None)


def test_a_tree_with_problems_is_saved_over_a_good_one_only_when_asked(
    workspace: Workspace,
) -> None:
    text, version = workspace.read("trees/hug.yaml")
    broken = text.replace("seconds: 2.0}", "seconds: 2.0, colour: red}")
    with pytest.raises(EditRefused) as refused:
        workspace.save("trees/hug.yaml", broken, version)
    assert refused.value.status == 409
    [problem] = refused.value.problems
    assert problem["message"] == "unknown parameter 'colour' for SetLed"
    assert problem["line"] == 21 and problem["file"] == "trees/hug.yaml"
    assert (workspace.folder / "trees" / "hug.yaml").read_text() == text

    saved = workspace.save("trees/hug.yaml", broken, version, over_problems=True)
    assert [p["message"] for p in saved.problems] == ["unknown parameter 'colour' for SetLed"]
    assert (workspace.folder / "trees" / "hug.yaml").read_text() == broken


def test_a_saved_tree_is_what_vest_run_loads(workspace: Workspace) -> None:
    text, version = workspace.read("trees/hug.yaml")
    workspace.save("trees/hug.yaml", text.replace("pink", "purple"), version)
    loader = TreeLoader(workspace.registry, robot_catalogue(CONFIG, workspace.registry))
    tree = loader.load(workspace.folder / "trees" / "hug.yaml")
    assert tree.name == "hug"
    assert tree.root.children[2].children[0].children[0].args["color"] == "purple"


def test_a_check_says_what_vest_validate_says_about_the_robot_s_pads(
    workspace: Workspace,
) -> None:
    text = "name: tickles\nrate_hz: 20\nroot:\n  Sequence:\n    - OnTouch: {pads: [elbow]}\n"
    [problem] = workspace.check("trees/tickles.yaml", text)
    assert problem["message"].startswith("no touch pad 'elbow' on the robot")
    assert "left_shoulder" in problem["hint"]
    assert problem["line"] == 5
    assert not (workspace.folder / "trees" / "tickles.yaml").exists()  # a check writes nothing


def test_a_fifo_named_like_a_tree_is_refused_not_waited_on(workspace: Workspace) -> None:
    os.mkfifo(workspace.folder / "trees" / "pipe.yaml")
    with pytest.raises(EditRefused, match=r"is not a regular file \(a FIFO\)"):
        workspace.read("trees/pipe.yaml")


def test_a_subtree_s_change_is_checked_in_the_trees_that_use_it(workspace: Workspace) -> None:
    text, version = workspace.read("trees/parts/greet.yaml")
    without_phrase = text.replace('  phrase: "Hello"\n', "")
    problems = workspace.check("trees/parts/greet.yaml", without_phrase)
    assert any(
        p["file"] == "trees/wave_greeting.yaml" and "unknown parameter 'phrase'" in p["message"]
        for p in problems
    )
    with pytest.raises(EditRefused) as refused:  # asked first: wave_greeting is fine today
        workspace.save("trees/parts/greet.yaml", without_phrase, version)
    assert refused.value.status == 409


def test_what_each_profile_sets_is_plain_json_even_a_nan(workspace, project) -> None:
    # a profile setting a number JSON has no form for is shown as nothing, never a 500
    (project / "trees" / "profiles" / "odd.yaml").write_text(
        "profile: odd\nparams:\n  hug_threshold_n: .nan\n  volume: 0.5\n"
    )
    profiles, problems = workspace.profiles()
    assert problems == []
    assert profiles["odd"] == {"hug_threshold_n": None, "volume": 0.5}
    assert profiles["child"]["hug_threshold_n"] == 2.0
    json.dumps(profiles, allow_nan=False)


def test_a_profile_that_does_not_load_is_named_with_its_place(workspace, project) -> None:
    # an unclosed list: the editor leaves the profile out and says where it broke
    (project / "trees" / "profiles" / "broken.yaml").write_text("profile: broken\nparams: [1, 2\n")
    profiles, problems = workspace.profiles()
    assert "broken" not in profiles and "child" in profiles
    assert len(problems) == 1
    assert problems[0].startswith("trees/profiles/broken.yaml:")
    assert problems[0].endswith("(the editor leaves this profile out)")
