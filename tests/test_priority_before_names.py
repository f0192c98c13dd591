"""Priority decides, never a tree's name or the order the trees were loaded.

The therapist's story: a new "That tickles!" tree (priority 30) and the shipped
touch_thanks (priority 40) both answer a pat. Whatever the new file is called, touch_thanks
speaks and "That tickles!" is never started in that step; the tickle tree knows it did
not act, so its rest does not start, and a later pat that touch_thanks (resting) does not
answer is its to answer. A tree cut short by a higher one lets go of what started it, or,
when it says ``when_interrupted: try_again``, starts it again once it is its turn.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]
THANKS = ROOT / "trees" / "touch_thanks.yaml"  # priority 40, rests 3 s
TICKLE = """\
name: tickle
rate_hz: 20
priority: {priority}
wait_for_turn_s: {wait}
when_interrupted: {when}
root:
  Sequence:
    - OnTouch: {{}}
    - Cooldown:
        seconds: 5
        child:
          Say: {{text: "That tickles!"}}
"""


def tickle(
    tmp_path: Path, file: str, *, priority: int = 30, wait: float = 0, when: str = "let_go"
) -> Path:
    path = tmp_path / file
    path.write_text(TICKLE.format(priority=priority, wait=wait, when=when))
    return path


def run(tmp_path: Path, capsys, trees: list[Path], *events: str) -> list[dict]:
    """The run's --json lines."""
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 8\nevents:\n" + "".join(f"  - {e}\n" for e in events))
    args = ["run", "--fast", "--json", "--speech", "text", "--scenario", str(scenario)]
    assert main([*args, "--trees", *map(str, trees)]) == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


def pat(at: float) -> str:
    return f"{{at: {at}, touch: {{pad: middle_back, seconds: 0.3}}}}"


def said(lines: list[dict]) -> list[tuple[float, str, str]]:
    return [
        (line["t"], line["tree"], line["args"]["text"])
        for line in lines
        if line["event"] == "action" and line["action"] == "say"
    ]


@pytest.mark.parametrize("file", ["a_tickle.yaml", "zz_tickle.yaml"])
def test_the_higher_priority_speaks_whatever_the_lower_tree_s_file_is_called(
    tmp_path, capsys, monkeypatch, file
):
    monkeypatch.chdir(ROOT)
    lines = run(tmp_path, capsys, [tickle(tmp_path, file), THANKS], pat(1.0))
    assert said(lines) == [(1.0, "touch_thanks", "Thank you")]  # "That tickles!" never began
    [turn] = [line for line in lines if line["event"] == "turn"]
    assert (turn["tree"], turn["turn"], turn["other"]) == ("tickle", "yields", "touch_thanks")
    assert not [line for line in lines if line["event"] == "outcome"]  # nothing cut short


def test_a_tree_that_yielded_did_not_act_so_its_rest_does_not_start(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    # at 1.0 both answer and tickle yields; at 2.5 touch_thanks rests (3 s): tickle, which
    # did not act at 1.0 and so is not resting, answers
    lines = run(tmp_path, capsys, [tickle(tmp_path, "tickle.yaml"), THANKS], pat(1.0), pat(2.5))
    assert said(lines) == [(1.0, "touch_thanks", "Thank you"), (2.5, "tickle", "That tickles!")]


BACK_THANKS = """\
name: back_thanks
rate_hz: 20
priority: 40
root:
  Sequence:
    - OnTouch: {except_pads: [left_shoulder]}
    - Say: {text: "Thank you"}
"""
SHOULDER_TICKLE = """\
name: tickle
rate_hz: 20
priority: 30
wait_for_turn_s: 3
when_interrupted: {when}
root:
  Sequence:
    - OnTouch: {{pads: [left_shoulder]}}
    - Cooldown:
        seconds: 5
        child:
          Say: {{text: "That tickles! Oh stop it please, I am so ticklish."}}
"""
TICKLISH = "That tickles! Oh stop it please, I am so ticklish."


def interrupted(tmp_path: Path, capsys, when: str) -> list[dict]:
    """The shoulder tickled at 1.0 (ten words: three seconds), the back patted at 2.0."""
    back = tmp_path / "back_thanks.yaml"
    back.write_text(BACK_THANKS)
    shoulder = tmp_path / "tickle.yaml"
    shoulder.write_text(SHOULDER_TICKLE.format(when=when))
    touch = "{{at: {at}, touch: {{pad: {pad}, seconds: 0.3}}}}"
    return run(
        tmp_path,
        capsys,
        [shoulder, back],
        touch.format(at=1.0, pad="left_shoulder"),
        touch.format(at=2.0, pad="middle_back"),
    )


def test_a_tree_cut_short_lets_go_of_what_started_it(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    lines = interrupted(tmp_path, capsys, "let_go")
    cut = [line for line in lines if line["event"] == "outcome" and line["outcome"] == "cut"]
    assert [(c["t"], c["tree"], c["why"]) for c in cut] == [
        (2.0, "tickle", "back_thanks interrupted it")
    ]
    assert said(lines) == [(1.0, "tickle", TICKLISH), (2.0, "back_thanks", "Thank you")]


def test_a_tree_that_tries_again_speaks_once_it_is_its_turn(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    lines = interrupted(tmp_path, capsys, "try_again")
    assert said(lines) == [
        (1.0, "tickle", TICKLISH),
        (2.0, "back_thanks", "Thank you"),
        (2.6, "tickle", TICKLISH),  # once "Thank you" (two words, 0.6 s) is over
    ]
    tries = [line for line in lines if line["event"] == "turn" and line["turn"] == "tries_again"]
    assert [(t["tree"], t["resource"], t["other"]) for t in tries] == [
        ("tickle", "speaker", "back_thanks")
    ]


def test_validate_warns_a_tree_that_would_try_again_without_waiting_for_its_turn(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    assert main(["validate", str(tickle(tmp_path, "tickle.yaml", when="try_again"))]) == 0
    err = capsys.readouterr().err
    assert "when_interrupted: try_again" in err
    assert "wait_for_turn_s" in err


WAITER = """\
name: {name}
rate_hz: {rate}
priority: {priority}
wait_for_turn_s: 5
root:
  Sequence:
    - OnTouch: {{pads: [{pad}]}}
    - Say: {{text: "{text}"}}
"""


def test_a_free_speaker_goes_to_the_highest_tree_waiting_for_it(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    trees = []
    for name, rate, priority, pad, text in (
        ("low", 20, 40, "left_shoulder", "low speaks"),
        ("middle", 7, 50, "right_shoulder", "middle speaks"),
        ("high", 3, 60, "upper_back", "high speaks at length, one two three four"),
    ):
        path = tmp_path / f"{name}.yaml"
        path.write_text(WAITER.format(name=name, rate=rate, priority=priority, pad=pad, text=text))
        trees.append(path)
    touch = "{{at: {at}, touch: {{pad: {pad}, seconds: 0.3}}}}"
    lines = run(
        tmp_path,
        capsys,
        trees,
        touch.format(at=1.0, pad="upper_back"),
        touch.format(at=1.5, pad="left_shoulder"),  # both wait for high's long sentence
        touch.format(at=1.6, pad="right_shoulder"),
    )
    assert [tree for _, tree, _ in said(lines)] == ["high", "middle", "low"]
    assert not [line for line in lines if line["event"] == "turn" and line["turn"] == "interrupts"]


def test_a_tree_tries_again_once_not_every_time_it_is_cut_short(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    back = tmp_path / "back_thanks.yaml"
    back.write_text(BACK_THANKS)
    shoulder = tmp_path / "tickle.yaml"
    shoulder.write_text(SHOULDER_TICKLE.format(when="try_again"))
    touch = "{{at: {at}, touch: {{pad: {pad}, seconds: 0.3}}}}"
    lines = run(
        tmp_path,
        capsys,
        [shoulder, back],
        touch.format(at=1.0, pad="left_shoulder"),
        touch.format(at=2.0, pad="middle_back"),  # cut short: tried again at 2.6...
        touch.format(at=3.0, pad="middle_back"),  # ...and cut short again: let go
    )
    assert [tree for _, tree, _ in said(lines)] == [
        "tickle",
        "back_thanks",
        "tickle",
        "back_thanks",
    ]


def test_a_round_that_only_set_a_value_before_giving_way_did_not_act(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    path = tmp_path / "tickle.yaml"
    path.write_text(
        TICKLE.format(priority=30, wait=0, when="let_go").replace(
            '          Say: {text: "That tickles!"}',
            "          Sequence:\n"
            "            - SetValue: {key: /vars/tickled, value: true}\n"
            '            - Say: {text: "That tickles!"}',
        )
    )
    lines = run(tmp_path, capsys, [path, THANKS], pat(1.0), pat(2.5))
    assert said(lines) == [(1.0, "touch_thanks", "Thank you"), (2.5, "tickle", "That tickles!")]
