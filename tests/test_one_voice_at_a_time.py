"""One voice at a time: the speaker, the face LEDs and each joint are shared by priority.

The therapist's story: "that tickles!" (a new tree) and the shipped touch_thanks both
answer a pat. Before, both spoke at once. Now the higher priority speaks; the lower one
yields (or waits its turn, as its tree says); a higher one interrupts a lower one, which
is halted cleanly with its arm back at rest. The timeline says who yielded to whom.
"""

from __future__ import annotations

import json
from pathlib import Path

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]
THANKS = ROOT / "trees" / "touch_thanks.yaml"  # priority 40

TICKLES = """\
name: tickles
rate_hz: 20
priority: {priority}
wait_for_turn_s: {wait}
root:
  Sequence:
    - OnTouch: {{pads: [left_shoulder]}}
    - Say: {{text: "Oh, that tickles!"}}
    - MoveServo: {{joint: left_arm, angle_deg: 60, speed_dps: 60}}
    - Say: {{text: "Stop it please, I am so ticklish."}}
    - MoveServo: {{joint: left_arm, angle_deg: 0, speed_dps: 60}}
"""

BACK_THANKS = """\
name: back_thanks
rate_hz: 20
priority: 40
root:
  Sequence:
    - OnTouch: {except_pads: [left_shoulder]}
    - Say: {text: "Thank you"}
"""

A_PAT = "{at: 1.0, touch: {pad: left_shoulder, seconds: 0.3}}"


def run(tmp_path: Path, capsys, trees: list[Path], *events: str, as_json: bool = False) -> str:
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 8\nevents:\n" + "".join(f"  - {e}\n" for e in events))
    args = [
        "run",
        "--fast",
        "--speech",
        "text",
        "--scenario",
        str(scenario),
        "--dialogs",
        "dialogs",
    ]
    assert main([*args, *(["--json"] if as_json else []), "--trees", *map(str, trees)]) == 0
    return capsys.readouterr()


def tickles(tmp_path: Path, *, priority: int, wait: float = 0) -> Path:
    path = tmp_path / "tickles.yaml"
    path.write_text(TICKLES.format(priority=priority, wait=wait))
    return path


def said(out: str) -> list[tuple[float, str, str]]:
    lines = [json.loads(line) for line in out.splitlines()]
    return [
        (a["t"], a["tree"], a["args"]["text"])
        for a in lines
        if a["event"] == "action" and a["action"] == "say"
    ]


def test_when_two_trees_answer_one_pat_the_higher_priority_speaks_and_the_lower_yields(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    trees = [THANKS, tickles(tmp_path, priority=20)]
    out = run(tmp_path, capsys, trees, A_PAT).out
    assert 'touch_thanks   says "Thank you"' in out
    assert "tickles        yields the speaker to touch_thanks: not saying" in out
    assert 'says "Oh, that tickles!"' not in out


def test_a_higher_priority_tree_interrupts_the_lower_one_whose_arm_goes_back_to_rest(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    back_thanks = tmp_path / "back_thanks.yaml"
    back_thanks.write_text(BACK_THANKS)
    trees = [back_thanks, tickles(tmp_path, priority=20)]
    # "Oh, that tickles!" (0.9 s), the arm up (1 s): at 3.0 s the arm is up and the robot
    # is mid-sentence when the back is patted
    out = run(
        tmp_path,
        capsys,
        trees,
        A_PAT.replace("1.0", "0.5"),
        "{at: 3.0, touch: {pad: middle_back, seconds: 0.3}}",
    ).out
    lines = out.splitlines()
    interrupt = next(i for i, line in enumerate(lines) if "interrupts tickles" in line)
    assert "back_thanks    interrupts tickles to use the speaker" in lines[interrupt]
    # what it was saying is cut short (and said so), its arm comes back to rest, and only
    # then does the higher tree speak
    assert "tickles        cut short: says" in lines[interrupt + 1]
    assert "(back_thanks interrupted it)" in lines[interrupt + 1]
    assert "tickles        turns left_arm to 0 deg" in lines[interrupt + 2]
    assert "(back to rest)" in lines[interrupt + 2]
    assert 'back_thanks    says "Thank you"' in lines[interrupt + 3]


def test_a_tree_that_waits_its_turn_speaks_when_the_speaker_is_free(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    trees = [THANKS, tickles(tmp_path, priority=20, wait=3)]
    text = run(tmp_path, capsys, trees, A_PAT).out
    assert "tickles        waits for the speaker: touch_thanks has it" in text
    answers = said(run(tmp_path, capsys, trees, A_PAT, as_json=True).out)
    assert [tree for _, tree, _ in answers][:2] == ["touch_thanks", "tickles"]
    thanks_at, tickles_at = answers[0][0], answers[1][0]
    assert tickles_at >= thanks_at + 0.6  # "Thank you" takes two words of 0.3 s


def test_trees_that_can_collide_with_no_priority_between_them_are_named_at_load(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    same = tickles(tmp_path, priority=40)
    err = run(tmp_path, capsys, [THANKS, same], A_PAT).err
    assert "trees 'touch_thanks' and 'tickles' both use the speaker at priority 40" in err
    assert "give one of them a higher 'priority:'" in err
