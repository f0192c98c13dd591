"""A tree file to the editor's outline and back: what was not changed stays as written."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from engine.editor.round_trip import OutlineError
from engine.editor.tree_yaml import TreeText
from engine.nodes.registry import default_registry

ROOT = Path(__file__).resolve().parents[2]
REGISTRY = default_registry()
TICKLES = """\
# trees/tickles.yaml: a therapist's own file, with comments
name: tickles
rate_hz: 20
wake_on: [/sensors/touch/pat]  # rest until a pat comes
priority: 42                   # above touch_thanks (40)
root:
  Sequence:
    - OnTouch: {pads: [left_shoulder, right_shoulder]}
    - Cooldown:
        seconds: 5
        counting_from: start   # 5 s after the last answer began
        child:
          Sequence:
            - Parallel:
                - Say: {text: "That tickles!"}  # said with the arm going up
                - MoveServo: {joint: left_arm, angle_deg: 45, speed_dps: 60}
            - MoveServo: {joint: left_arm, angle_deg: 0, speed_dps: 60}
"""


def shipped_trees() -> list[Path]:
    return sorted(p for p in (ROOT / "trees").rglob("*.yaml") if "root:" in p.read_text())


@pytest.mark.parametrize("path", shipped_trees(), ids=lambda p: p.name)
def test_opening_and_saving_unchanged_leaves_every_shipped_tree_byte_for_byte(path: Path) -> None:
    text = path.read_text()
    tree = TreeText(text, REGISTRY)
    assert tree.written(tree.outline()) == text
    touched = copy.deepcopy(tree.outline())
    touched["settings"]["unknown"] = 1  # not a setting the editor changes: a rewrite all the same
    assert tree.written(touched) == text


def test_a_changed_number_keeps_every_comment_and_the_other_lines() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    cooldown = outline["root"]["children"][1]
    assert cooldown["type"] == "Cooldown" and cooldown["args"] == {
        "seconds": 5,
        "counting_from": "start",
    }
    cooldown["args"]["seconds"] = 8
    written = tree.written(outline)
    assert written == TICKLES.replace("seconds: 5\n", "seconds: 8\n")


def test_a_node_added_moved_and_removed_changes_only_its_own_lines() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    inner = outline["root"]["children"][1]["children"][0]["children"]
    parallel = inner[0]["children"]
    parallel.append({"type": "SetLed", "name": None, "args": {"color": "pink", "seconds": 2}})
    parallel[0], parallel[1] = parallel[1], parallel[0]  # the arm first, then the words
    written = tree.written(outline)
    assert '- Say: {text: "That tickles!"}  # said with the arm going up' in written
    assert written.index("MoveServo: {joint: left_arm, angle_deg: 45") < written.index("Say:")
    assert "- SetLed: {color: pink, seconds: 2}\n" in written
    assert written.startswith("# trees/tickles.yaml: a therapist's own file, with comments\n")

    outline["root"]["children"][1]["children"][0]["children"].pop()  # the arm stays up
    assert "angle_deg: 0" not in tree.written(outline)


def test_a_named_node_and_a_new_list_read_as_a_person_writes_them() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    outline["root"]["name"] = "a pat on a shoulder"
    outline["root"]["children"][0]["args"]["pads"] = ["left_shoulder"]
    written = tree.written(outline)
    assert '  Sequence:\n    name: "a pat on a shoulder"\n    children:\n' in written
    assert "- OnTouch: {pads: [left_shoulder]}\n" in written
    again = TreeText(written, REGISTRY).outline()
    assert again["root"]["name"] == "a pat on a shoulder"
    assert again["root"]["children"][0]["args"] == {"pads": ["left_shoulder"]}


def test_settings_change_in_place_and_one_taken_out_is_gone() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    outline["settings"]["priority"] = 45
    del outline["settings"]["wake_on"]
    written = tree.written(outline)
    assert "priority: 45                   # above touch_thanks (40)\n" in written
    assert "wake_on" not in written


@pytest.mark.parametrize(
    "text, why",
    [
        ("root: [", "not YAML"),
        ("name: x\nrate_hz: 3\n", "not a tree file"),
        ("- 1\n", "not a tree"),
    ],
)
def test_what_is_not_a_tree_file_is_said_in_words(text: str, why: str) -> None:
    with pytest.raises(OutlineError, match=why):
        TreeText(text, REGISTRY)


def test_an_outline_without_types_is_refused_with_its_place() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    outline["root"]["children"][0] = {"args": {}}
    with pytest.raises(OutlineError, match="root/0: a node needs a type"):
        tree.written(outline)


def test_a_node_given_twice_is_written_twice_not_as_a_yaml_alias() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    touch = outline["root"]["children"][0]
    outline["root"]["children"].append(copy.deepcopy(touch))  # the same id twice
    written = tree.written(outline)
    assert "&" not in written and "*" not in written
    assert written.count("- OnTouch: {pads: [left_shoulder, right_shoulder]}") == 2


def test_a_file_with_yaml_anchors_is_left_to_hand_editing() -> None:
    shared = TICKLES.replace(
        '- Say: {text: "That tickles!"}', '- &said Say: {text: "That tickles!"}'
    ).replace(
        "- MoveServo: {joint: left_arm, angle_deg: 0",
        "- *said\n            - MoveServo: {joint: left_arm, angle_deg: 0",
    )
    with pytest.raises(OutlineError, match="anchors"):
        TreeText(shared, REGISTRY)


def test_a_thousand_aliases_deep_are_refused_before_they_are_expanded() -> None:
    laughs = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 10)}]\n" for i in range(8)
    )
    with pytest.raises(OutlineError, match="anchors"):
        TreeText(laughs + "root: {Sequence: [*i]}\n", REGISTRY)


def test_windows_line_ends_stay_windows_line_ends_after_an_edit() -> None:
    windows = TICKLES.replace("\n", "\r\n")
    tree = TreeText(windows, REGISTRY)
    outline = tree.outline()
    outline["settings"]["priority"] = 43
    written = tree.written(outline)
    assert written == windows.replace("priority: 42 ", "priority: 43 ")


def test_children_under_a_leaf_or_two_under_a_decorator_are_refused() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    say = {"type": "Say", "name": None, "args": {"text": "hi"}, "children": []}
    outline["root"]["children"][0]["children"] = [say]  # under OnTouch
    with pytest.raises(OutlineError, match="OnTouch takes no node under it, got 1"):
        tree.written(outline)
    outline = tree.outline()
    outline["root"]["children"][1]["children"].append(say)  # a second child of Cooldown
    with pytest.raises(OutlineError, match="Cooldown takes one node under it, got 2"):
        tree.written(outline)


def test_an_outline_nested_past_vest_s_limit_is_refused_in_words() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    deepest = outline["root"]
    for _ in range(150):
        inner = {"type": "Sequence", "name": None, "args": {}, "children": []}
        deepest["children"] = [inner]
        deepest = inner
    with pytest.raises(OutlineError, match="nested more than 100 deep"):
        tree.written(outline)


HUG_PARAMS = """\
name: hug
rate_hz: 20
params:
  hug_threshold_n: 3.0   # a gentle hug is 2 to 4 N
  hug_phrase: "I love hugs!"
root:
  Check: {key: /sensors/force/left_n, above: "${hug_threshold_n}"}
"""


def test_a_tree_s_params_are_in_the_outline_and_change_in_place_with_their_comments() -> None:
    tree = TreeText(HUG_PARAMS, REGISTRY)
    outline = tree.outline()
    assert outline["params"] == {"hug_threshold_n": 3.0, "hug_phrase": "I love hugs!"}
    outline["params"]["hug_threshold_n"] = 4.5
    assert tree.written(outline) == HUG_PARAMS.replace("3.0   #", "4.5   #")


def test_params_added_to_a_tree_without_go_above_its_root_and_the_last_one_out_takes_them() -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline()
    assert outline["params"] == {}
    outline["params"] = {"tickle_rest_s": 5}
    written = tree.written(outline)
    assert "priority: 42                   # above touch_thanks (40)\nparams:\n" in written
    assert "  tickle_rest_s: 5\nroot:\n" in written
    again = TreeText(written, REGISTRY)
    emptied = again.outline()
    emptied["params"] = {}
    assert again.written(emptied) == TICKLES


@pytest.mark.parametrize("params", [["a"], {"": 1} | {1: 2}, "x"], ids=["list", "key", "text"])
def test_params_that_are_not_names_to_values_are_refused(params: object) -> None:
    tree = TreeText(TICKLES, REGISTRY)
    outline = tree.outline() | {"params": params}
    with pytest.raises(OutlineError, match="params must be a mapping of names to values"):
        tree.written(outline)
