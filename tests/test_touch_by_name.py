"""Touch by name: the robot config names each pad; trees answer a new pat on a named pad
in one line; a hand resting on a pad is one pat; a squeeze is an event too."""

from __future__ import annotations

import json
from pathlib import Path

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]
SIM = ROOT / "examples" / "robots" / "sim.yaml"

TICKLES = """\
name: tickles
rate_hz: 20
root:
  Sequence:
    - OnTouch: {pads: [left_shoulder, right_shoulder]}
    - Say: {text: "That tickles!"}
"""

BACK_ONLY = """\
name: back_rub
rate_hz: 20
root:
  Sequence:
    - OnTouch: {except_pads: [left_shoulder, right_shoulder], save_as: /vars/back_rub/pad}
    - Say: {text: "Thank you for the back rub on {/vars/back_rub/pad}."}
"""

SQUEEZE = """\
name: squeezed
rate_hz: 20
root:
  Sequence:
    - OnEvent: {key: /sensors/force/squeeze, save_as: /vars/squeezed/side}
    - Say: {text: "Ouch, my {/vars/squeezed/side} side!"}
"""


def scenario(tmp_path: Path, *events: str, duration_s: float = 6.0) -> Path:
    path = tmp_path / "scenario.yaml"
    path.write_text(f"duration_s: {duration_s}\nevents:\n" + "".join(f"  - {e}\n" for e in events))
    return path


def tree(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return path


def said(capsys, trees: list[Path], scenario_path: Path) -> list[tuple[float, str, str]]:
    args = ["run", "--fast", "--json", "--hardware", str(SIM), "--scenario", str(scenario_path)]
    assert main([*args, "--speech", "text", "--trees", *map(str, trees)]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    return [
        (a["t"], a["tree"], a["args"]["text"])
        for a in lines
        if a["event"] == "action" and a["action"] == "say"
    ]


def test_a_pat_on_a_named_shoulder_is_answered_and_a_pat_on_the_back_is_not(tmp_path, capsys):
    story = scenario(
        tmp_path,
        "{at: 1.0, touch: {pad: left_shoulder, seconds: 0.3}}",
        "{at: 2.0, touch: {pad: middle_back, seconds: 0.3}}",
        "{at: 3.0, touch: {pad: 1, seconds: 0.3}}",  # electrode 1: right_shoulder
    )
    answers = said(capsys, [tree(tmp_path, "tickles", TICKLES)], story)
    assert [text for _, _, text in answers] == ["That tickles!", "That tickles!"]
    assert [round(t) for t, _, _ in answers] == [1, 3]


def test_a_hand_resting_on_the_shoulder_for_five_seconds_is_one_pat(tmp_path, capsys):
    story = scenario(tmp_path, "{at: 0.5, touch: {pad: right_shoulder, seconds: 5.0}}")
    answers = said(capsys, [tree(tmp_path, "tickles", TICKLES)], story)
    assert [text for _, _, text in answers] == ["That tickles!"]


def test_any_pad_but_the_shoulders_names_the_pad_it_was(tmp_path, capsys):
    story = scenario(
        tmp_path,
        "{at: 1.0, touch: {pad: right_shoulder, seconds: 0.3}}",
        "{at: 2.0, touch: {pad: lower_back, seconds: 0.3}}",
    )
    answers = said(capsys, [tree(tmp_path, "back_rub", BACK_ONLY)], story)
    assert [text for _, _, text in answers] == ["Thank you for the back rub on lower_back."]


def test_a_squeeze_of_one_side_is_an_event_naming_the_side_once_however_long_it_lasts(
    tmp_path, capsys
):
    story = scenario(tmp_path, "{at: 1.0, squeeze: {left_n: 6.0, right_n: 0.0, seconds: 3.0}}")
    answers = said(capsys, [tree(tmp_path, "squeezed", SQUEEZE)], story)
    assert [text for _, _, text in answers] == ["Ouch, my left side!"]


def test_a_pad_the_robot_does_not_have_is_refused_with_its_place_and_the_nearest_name(
    tmp_path, capsys
):
    typo = tree(tmp_path, "tickles", TICKLES.replace("left_shoulder", "left_sholder"))
    story = scenario(tmp_path, "{at: 1.0, touch: {pad: middle_back}}")
    args = ["run", "--fast", "--hardware", str(SIM), "--scenario", str(story), "--trees", str(typo)]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert f"{typo}:5:7: no touch pad 'left_sholder'" in err
    assert "did you mean 'left_shoulder'" in err


def test_validate_names_a_scenario_pad_the_robot_does_not_have(tmp_path, capsys):
    story = scenario(tmp_path, "{at: 1.0, touch: {pad: tummy}}")
    assert main(["validate", str(story)]) == 1
    err = capsys.readouterr().err + capsys.readouterr().out
    assert "no touch pad 'tummy'" in err
    assert "pads: left_shoulder, right_shoulder" in err


def test_a_config_giving_one_name_to_two_pads_is_refused_with_its_place(tmp_path, capsys):
    config = SIM.read_text().replace("left_back, right_back", "left_back, left_back")
    path = tmp_path / "robot.yaml"
    path.write_text(config)
    assert main(["validate", str(path)]) == 1
    err = capsys.readouterr().err + capsys.readouterr().out
    assert "pad name 'left_back' is given to electrodes 5 and 6" in err
