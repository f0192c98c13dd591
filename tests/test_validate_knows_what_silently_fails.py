"""`vest validate` (and `vest run`, with the same checks) names what would load fine and
then silently never work: a /vars/ key no tree writes, a comparison of the wrong kind, a
joint or angle the robot does not have, typographic quotes in spoken text, buttons and
safety settings that cannot work."""

from __future__ import annotations

from pathlib import Path

from engine.cli import main

ROOT = Path(__file__).resolve().parents[1]
SIM = ROOT / "examples" / "robots" / "sim.yaml"


def validate(tmp_path: Path, capsys, files: dict[str, str], *extra: str) -> tuple[int, str]:
    for name, text in files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    code = main(["validate", *extra, *(str(tmp_path / name) for name in files)])
    out, err = capsys.readouterr()
    return code, out + err


WRITER = """\
name: game
rate_hz: 10
root:
  Sequence:
    - OnTouch: {pads: [left_shoulder]}
    - SetValue: {key: /vars/game/started, value: true}
"""


def test_a_misspelt_variable_that_no_tree_writes_is_named_with_the_nearest(tmp_path, capsys):
    reader = """\
name: praise
rate_hz: 10
root:
  Sequence:
    - Check: {key: /vars/game/stared, equals: true}
    - Say: {text: "Well done"}
"""
    code, told = validate(tmp_path, capsys, {"game.yaml": WRITER, "praise.yaml": reader})
    assert code == 1
    assert "praise.yaml:5:7: /vars/game/stared is read but no tree writes it" in told
    assert "did you mean '/vars/game/started'" in told


def test_comparing_a_true_false_variable_with_the_text_true_is_named(tmp_path, capsys):
    reader = """\
name: praise
rate_hz: 10
root:
  Sequence:
    - Check: {key: /vars/game/started, equals: "true"}
    - Say: {text: "Well done"}
"""
    code, told = validate(tmp_path, capsys, {"game.yaml": WRITER, "praise.yaml": reader})
    assert code == 1
    assert "praise.yaml:5:7: /vars/game/started holds true/false (written by tree 'game'" in told
    assert "never 'true' (write true or false without quotes)" in told


def test_a_joint_the_robot_lacks_and_an_angle_beyond_its_servo_are_named(tmp_path, capsys):
    tree = """\
name: arms
rate_hz: 10
root:
  Sequence:
    - MoveServo: {joint: left_am, angle_deg: 10}
    - MoveServo: {joint: right_arm, angle_deg: 120}
"""
    code, told = validate(tmp_path, capsys, {"arms.yaml": tree})
    assert code == 1
    assert "arms.yaml:5:7: the robot has no joint 'left_am' (did you mean 'left_arm'?)" in told
    assert "arms.yaml:6:7: right_arm to 120 deg would always be refused: its servo allow" in told


def test_curly_quotes_in_spoken_text_are_a_warning_not_a_failure(tmp_path, capsys):
    tree = """\
name: tickles
rate_hz: 10
root:
  Say: {text: "\u201cThat tickles!\u201d"}
"""
    code, told = validate(tmp_path, capsys, {"tickles.yaml": tree})
    assert code == 0
    assert "warning: " in told and "tickles.yaml:4:3: typographic quotes" in told


def test_a_button_condition_that_cannot_work_is_named(tmp_path, capsys):
    buttons = """\
buttons:
  - {label: A, say: a, when: {paused: "false"}}
  - {label: B, say: b, when: {running: game, paused: true}}
  - {label: C, say: c, when: {running: ""}}
"""
    code, told = validate(tmp_path, capsys, {"buttons.yaml": buttons})
    assert code == 1
    assert "paused: must be true or false, got 'false'" in told
    assert "when: takes one condition, got running, paused" in told
    assert "running: takes a tree's name" in told


def test_safety_limits_that_would_keep_an_arm_from_rest_or_its_speed_are_refused(tmp_path, capsys):
    config = SIM.read_text().replace(
        "  slow_speed_dps: 30", "  slow_speed_dps: 100\n  joint_limits: {left_arm: [10, 70]}"
    )
    code, told = validate(tmp_path, capsys, {"robot.yaml": config})
    assert code == 1
    told = " ".join(told.split())
    assert "joint_limits of 'left_arm' [10, 70] leave out its home_deg 0" in told


def test_a_pad_named_like_another_electrode_is_refused(tmp_path, capsys):
    config = SIM.read_text().replace("pad_names: [left_shoulder,", "pad_names: [pad_1,")
    code, told = validate(tmp_path, capsys, {"robot.yaml": config})
    assert code == 1
    assert "pad name 'pad_1' (electrode 0) is the name of another electrode" in told
