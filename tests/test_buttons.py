"""Buttons that take over: the therapist's story.

A button file (trees/buttons/session.yaml) names what each button does. A press pre-empts
the behaviors that want the same speaker, LEDs or joint (cleanly: lights off, joints to
rest), is carried out within a tick, shows in the timeline, and is kept in a recording.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording
from engine.recording.told import told_events
from engine.session.events import ButtonPressed

ROOT = Path(__file__).resolve().parents[1]
BUTTONS = ROOT / "trees" / "buttons" / "session.yaml"


def run(tmp_path: Path, capsys, *events: str, extra: tuple[str, ...] = ()) -> tuple[str, str]:
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 8\nevents:\n" + "".join(f"  - {e}\n" for e in events))
    code = main(["run", "--fast", "--speech", "text", "--scenario", str(scenario), *extra])
    out, err = capsys.readouterr()
    assert code == 0, err
    return out, err


STORY = "Once upon a time a little robot told a very long story to everyone it met."


def reports(out: str) -> list[str]:
    """The robot's reports to the operator, as the timeline words them (time left out)."""
    return [" ".join(line.split()[1:]) for line in out.splitlines() if " reports " in line]


def lines_after(out: str, text: str) -> list[str]:
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if text in line)
    return [" ".join(line.split()[1:]) for line in lines[start:]]


def test_a_button_pressed_mid_hug_speaks_at_once_and_the_hug_gives_way(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    out, _ = run(
        tmp_path,
        capsys,
        "{at: 1.0, squeeze: {left_n: 6.0, right_n: 6.0, seconds: 2.0}}",
        "{at: 1.2, press: Well done}",
    )
    assert lines_after(out, "presses the button")[:9] == [
        "scenario presses the button 'Well done'",  # a scripted press: the scenario's
        "buttons interrupts hug to use the face LEDs",  # the button's green replaces pink
        "hug cut short: lights the face pink for 2 s (buttons interrupted it)",
        'hug cut short: says "I love hugs!" (buttons interrupted it)',
        "buttons lights the face green for 1 s",
        'buttons says "Well done! That was great."',
        # the hug, still going on, gives way once for each (no stutter), and lights the
        # face again once the button's green is over
        "hug yields the face LEDs to buttons: not lighting the face pink",
        "hug yields the speaker to buttons: not saying 'I love hugs!'",
        "hug lights the face pink for 2 s",
    ]
    pressed_at = next(line for line in out.splitlines() if 'says "Well done!' in line)
    assert pressed_at.split()[0] == "1.20"  # within the tick the press came in
    answered_at = next(line for line in out.splitlines() if 'hug            says "I' in line)
    assert answered_at.split()[0] == "1.00"  # the first answer, before the press


def test_while_paused_a_pat_is_not_answered_not_even_after_resuming(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    out, _ = run(
        tmp_path,
        capsys,
        "{at: 1.0, press: Pause}",
        "{at: 2.0, touch: {pad: middle_back}}",
        "{at: 3.0, press: Resume}",
        "{at: 4.0, touch: {pad: upper_back}}",
    )
    said = [line for line in out.splitlines() if "touch_thanks   says" in line]
    assert [line.split()[0] for line in said] == ["4.00"]


def test_an_operator_s_commands_while_paused_are_refused_and_told_at_once(
    tmp_path, capsys, monkeypatch
):
    # the operator is never left waiting: the command the pause cut, the one queued behind
    # it and the one sent during the pause are each reported; after Resume one is carried out
    monkeypatch.chdir(ROOT)
    out, _ = run(
        tmp_path,
        capsys,
        f'{{at: 1.0, cloud: {{id: c1, type: say, args: {{text: "{STORY}"}}}}}}',
        "{at: 1.5, cloud: {id: c2, type: led, args: {color: red}}}",
        "{at: 2.0, press: Pause}",
        "{at: 2.5, cloud: {id: c3, type: led, args: {color: blue}}}",
        "{at: 3.0, press: Resume}",
        "{at: 4.0, cloud: {id: c4, type: led, args: {color: green}}}",
    )
    paused = "the therapist paused the behaviors"
    assert reports(out) == [
        f"iot_command reports c1 failed: {{'error': 'cut short: {paused}'}}",
        f"iot_command reports c2 failed: {{'error': 'not carried out: {paused}'}}",
        f"iot_command reports c3 failed: {{'error': 'not carried out: {paused}'}}",
        "iot_command reports c4 succeeded",
    ]


def test_a_command_that_came_too_late_for_the_session_is_told_not_carried_out(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    out, _ = run(
        tmp_path,
        capsys,
        f'{{at: 7.5, cloud: {{id: c1, type: say, args: {{text: "{STORY}"}}}}}}',
        "{at: 7.6, cloud: {id: c2, type: led, args: {color: red}}}",  # behind it: unread
    )
    assert reports(out) == [
        "iot_command reports c1 failed: {'error': 'cut short: its tree was stopped'}",
        "iot_command reports c2 failed: {'error': 'not carried out: the session ended'}",
    ]


def test_stop_everything_ends_a_buttons_action_and_pauses_the_behaviors(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    out, _ = run(
        tmp_path,
        capsys,
        "{at: 1.0, press: Look ahead}",
        "{at: 1.0, gesture: wave}",
        "{at: 1.5, press: Stop everything}",
        "{at: 2.0, gesture: wave}",
    )
    assert "buttons        pauses the behaviors" in out
    stop = "presses the button 'Stop everything': everything stops, and the behaviors stay"
    assert stop + " paused until resumed" in out
    # the wave at 1.0 is greeted; the one at 2.0, after the stop, is not
    assert [line.split()[0] for line in out.splitlines() if "wave_greeting  says" in line] == [
        "1.00"
    ]


def test_the_envelope_refuses_a_button_s_arm_move_while_someone_leans_on_the_chest(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    buttons = tmp_path / "buttons.yaml"
    buttons.write_text("buttons:\n  - {label: Arm up, move: {joint: left_arm, angle_deg: 45}}\n")
    out, _ = run(
        tmp_path,
        capsys,
        "{at: 1.0, obstacle: {center_mm: 80, seconds: 2.0}}",
        "{at: 1.5, press: Arm up}",
        extra=("--buttons", str(buttons), "--view-port", "0"),
    )
    refused = next(line for line in out.splitlines() if "could not" in line)
    assert refused.split()[1] == "buttons"
    assert "safety: something is" in refused and "the arms stay still" in refused


def test_a_press_is_kept_in_the_session_recording(
    tmp_path, capsys, monkeypatch, the_site_key: SiteKey
):
    monkeypatch.chdir(ROOT)
    recorded = tmp_path / "session.db"
    run(tmp_path, capsys, "{at: 1.0, press: Hello}", extra=("--record", str(recorded)))
    recording = Recording.open(recorded, the_site_key)
    try:
        [press] = [e for e in told_events(recording) if isinstance(e, ButtonPressed)]
        assert (press.t_s, press.label, press.by) == (1.0, "Hello", "scenario")
        said = [a for a in recording.actions() if a.action == "say"]
        assert [(a.tree, a.args["text"]) for a in said] == [
            ("buttons", "Hello! I am happy to see you.")
        ]
    finally:
        recording.close()


def test_a_button_pressed_while_a_game_waits_for_a_hand_leaves_the_game_going(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    out, _ = run(
        tmp_path,
        capsys,
        "{at: 0.5, show_hand: {fingers: 5, seconds: 1.0}}",  # the game begins
        "{at: 4.0, press: Show me your hand}",  # shown only while the game runs
        "{at: 6.0, show_hand: {fingers: 3, seconds: 1.5}}",
        extra=("--duration", "9"),
    )
    assert 'buttons        says "Can you show me your hand?"' in out
    assert "interrupts finger_game" not in out
    assert 'finger_game    says "Yes! That\'s three. Well done!"' in out


def test_a_button_not_shown_now_does_nothing_and_says_so(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    out, _ = run(tmp_path, capsys, "{at: 1.0, press: Show me your hand}")  # no game runs
    assert (
        "scenario       presses the button 'Show me your hand', which is not shown now: "
        "nothing done" in out
    )
    assert "Can you show me your hand?" not in out


def test_a_scenario_pressing_a_button_the_file_lacks_is_refused_with_its_place(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 2\nevents:\n  - {at: 1.0, press: Wel done}\n")
    assert main(["run", "--fast", "--scenario", str(scenario)]) == 1
    err = capsys.readouterr().err
    assert f"{scenario}:3:5: no button labelled 'Wel done'" in err
    assert "did you mean 'Well done'" in err


def check(tmp_path: Path, capsys, text: str) -> str:
    path = tmp_path / "buttons.yaml"
    path.write_text(text)
    assert main(["validate", str(path)]) == 1
    return capsys.readouterr().err


def test_mistakes_in_a_button_file_are_named_at_their_place(tmp_path, capsys):
    err = check(
        tmp_path,
        capsys,
        "buttons:\n"
        "  - {label: Hi, say: Hi!, led: green}\n"  # two things at once
        "  - {label: Ho, key: ctrl, say: Ho}\n"  # not a key
        "  - {label: Go, do: pasue}\n"  # a typo
        "  - {label: Up, move: {joint: left_arm, angle: 45}}\n"  # a node's parameter
        "  - {label: Yo, say: Yo}\n"
        "  - {label: Yo, say: again}\n",  # two labels alike
    )
    assert "buttons.yaml:2:5: button 'Hi' must do one thing: it gives say, led" in err
    assert "buttons.yaml:3:22: key 'ctrl' is not a key of the keyboard" in err
    assert "buttons.yaml:4:21: do: must be one of pause, resume, stop, got 'pasue'" in err
    assert "did you mean 'pause'" in err
    assert "buttons.yaml:5:41: unknown parameter 'angle' for MoveServo" in err
    assert "buttons.yaml:7:5: two buttons are labelled 'Yo'" in err


def test_the_shipped_button_file_is_valid(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["validate", str(BUTTONS)]) == 0


def test_validate_checks_a_scenario_s_presses_against_the_buttons_given(tmp_path, capsys):
    buttons = tmp_path / "sam.yaml"
    buttons.write_text("buttons:\n  - {label: Hello Sam, say: Hello Sam!}\n")
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text("duration_s: 2\nevents:\n  - {at: 1.0, press: Hello Sam}\n")
    assert main(["validate", "--buttons", str(buttons), str(scenario)]) == 0
    scenario.write_text("duration_s: 2\nevents:\n  - {at: 1.0, press: Hello Tom}\n")
    assert main(["validate", "--buttons", str(buttons), str(scenario)]) == 1
    assert "no button labelled 'Hello Tom'" in capsys.readouterr().err


@pytest.mark.realtime
def test_buttons_alone_in_real_time_say_that_no_scenario_plays(capsys, monkeypatch):
    # --help says the demo is the default scenario; with the buttons in real time the
    # therapist leads instead, and the run says so rather than dropping the demo silently
    monkeypatch.chdir(ROOT)
    args = ["run", "--speech", "text", "--buttons", "trees/buttons/session.yaml"]
    assert main([*args, "--view-port", "0", "--duration", "0.3"]) == 0
    out, err = capsys.readouterr()
    assert "no scenario plays: the therapist's buttons lead the session" in err
    assert "world" not in out  # nothing of the demo happened
