"""Bad dialog, scenario and profile files: ``file:line:column: message (hint)`` each."""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import DialogLibrary, load_dialog
from engine.files.problems import LoadError
from engine.loader.substitution import load_profile
from engine.scenario.scenario_file import load_scenario


def problems(
    tmp_path: Path, read: Callable[[Path, str], Any], text: str, name: str = "file.yaml"
) -> list[str]:
    """Every problem ``read`` finds in ``text``, as the lines a person would read."""
    path = tmp_path / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    with pytest.raises(LoadError) as caught:
        read(path, name)
    return [str(problem) for problem in caught.value.problems]


def dialog(path: Path, shown: str) -> Any:
    return load_dialog(path, default_catalogue(), shown)


# -- dialogs ---------------------------------------------------------------------------------
def test_an_unknown_concept_suggests_the_nearest(tmp_path: Path) -> None:
    [problem] = problems(
        tmp_path,
        dialog,
        """\
        dialog: session
        concepts:
          you_name: ["your name", "you called"]
        rules:
          - hear: ["what is ~your_name"]
            say: "My name is H B S 2"
        """,
    )
    assert problem.startswith("file.yaml:5:12: unknown concept '~your_name'")
    assert "did you mean 'you_name'?" in problem


def test_a_rule_without_an_answer_is_named(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        dialog,
        """\
        dialog: session
        rules:
          - hear: ["hello"]
        """,
    ) == ["file.yaml:3:5: rule has no 'say:' (write what the robot answers)"]


def test_a_rule_without_phrases_is_named(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        dialog,
        """\
        dialog: session
        rules:
          - say: "Hello!"
        """,
    ) == ["file.yaml:3:5: rule has no 'hear:' (list the phrases that trigger it)"]


def test_a_sensor_that_cannot_be_read_on_request_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        dialog,
        """\
        dialog: session
        rules:
          - hear: ["how far is it"]
            read: ultrasonic
            say: "It is {ultrasound_cm:.0f} centimetres away"
        """,
    ) == ["file.yaml:4:11: cannot read 'ultrasonic' on request (did you mean 'ultrasound'?)"]


def test_an_unknown_field_in_an_answer_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        dialog,
        """\
        dialog: session
        rules:
          - hear: ["how warm is it"]
            read: temperature
            say: "It is {temprature_f:.0f} degrees"
        """,
    ) == ["file.yaml:5:10: unknown template field {temprature_f} (did you mean 'temperature_f'?)"]


def test_a_misspelled_rule_field_suggests_the_nearest(tmp_path: Path) -> None:
    assert "file.yaml:4:5: unknown rule field 'sya' (did you mean 'say'?)" in problems(
        tmp_path,
        dialog,
        """\
        dialog: session
        rules:
          - hear: ["hello"]
            sya: "Hello!"
        """,
    )


def test_a_dialog_without_rules_is_named(tmp_path: Path) -> None:
    assert problems(tmp_path, dialog, "dialog: session\n") == [
        "file.yaml:1:1: a dialog needs 'rules:' (add a list of hear/say rules)"
    ]


def test_a_dialogs_folder_reports_the_problems_of_every_file(tmp_path: Path) -> None:
    (tmp_path / "a.yaml").write_text("dialog: a\nrules:\n  - hear: [hi]\n", encoding="utf-8")
    (tmp_path / "b.yaml").write_text("dialog: b\nrules: 5\n", encoding="utf-8")
    with pytest.raises(LoadError) as caught:
        DialogLibrary.from_folder(tmp_path, default_catalogue())
    assert [problem.mark.file for problem in caught.value.problems] == [
        str(tmp_path / "a.yaml"),
        str(tmp_path / "b.yaml"),
    ]


# -- scenarios -------------------------------------------------------------------------------
def test_an_unknown_event_kind_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        load_scenario,
        """\
        duration_s: 10
        events:
          - {at: 1.0, gesure: wave}
        """,
    ) == ["file.yaml:3:15: unknown event 'gesure' (did you mean 'gesture'?)"]


def test_a_field_that_may_be_empty_keeps_its_event(tmp_path: Path) -> None:
    # a cloud command's args: null is "no arguments", not a problem: the event is played
    path = tmp_path / "scenario.yaml"
    path.write_text("duration_s: 4\nevents:\n  - {at: 1.0, cloud: {type: read, args: null}}\n")
    [event] = load_scenario(path).events
    assert (event.kind, event.value["args"]) == ("cloud", None)


def test_an_unknown_gesture_suggests_the_nearest(tmp_path: Path) -> None:
    [problem] = problems(
        tmp_path,
        load_scenario,
        """\
        duration_s: 10
        events:
          - {at: 1.0, gesture: wav}
        """,
    )
    assert problem.startswith("file.yaml:3:24: 'gesture' must be one of wave, swipe_left")
    assert "did you mean 'wave'?" in problem


def test_an_event_without_a_time_is_named(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        load_scenario,
        """\
        duration_s: 10
        events:
          - {gesture: wave}
        """,
    ) == ["file.yaml:3:5: event has no 'at:' (seconds from the start, e.g. at: 1.5)"]


def test_an_event_after_the_end_is_named(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        load_scenario,
        """\
        duration_s: 10
        events:
          - {at: 12.0, gesture: wave}
        """,
    ) == ["file.yaml:3:5: event at 12 s is after the scenario ends (10 s) (raise duration_s)"]


@pytest.mark.parametrize("body", ["{}", "{c: 20, f: 70}"])
def test_a_temperature_needs_celsius_or_fahrenheit(tmp_path: Path, body: str) -> None:
    assert problems(
        tmp_path,
        load_scenario,
        f"""\
        duration_s: 10
        events:
          - {{at: 1.0, temperature: {body}}}
        """,
    ) == ["file.yaml:3:28: temperature takes c or f (e.g. {c: 22.2})"]


def test_a_touch_pad_beyond_the_twelve_is_named(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        load_scenario,
        """\
        duration_s: 10
        events:
          - {at: 1.0, touch: {pad: 12}}
        """,
    ) == ["file.yaml:3:28: 'pad' must be at most 11, got 12"]


def test_a_scenario_without_a_duration_is_named(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        load_scenario,
        """\
        events:
          - {at: 1.0, gesture: wave}
        """,
    ) == ["file.yaml:1:1: a scenario needs 'duration_s:' (seconds, e.g. 20)"]


# -- profiles --------------------------------------------------------------------------------
def test_a_misspelled_profile_field_suggests_the_nearest(tmp_path: Path) -> None:
    assert problems(
        tmp_path,
        load_profile,
        """\
        profile: kid
        parms:
          rest_s: 3
        """,
    ) == [
        "file.yaml:1:1: a profile needs 'params:' (list the values it changes)",
        "file.yaml:2:1: unknown profile field 'parms' (did you mean 'params'?)",
    ]


def test_profile_params_must_be_a_mapping(tmp_path: Path) -> None:
    assert problems(tmp_path, load_profile, "profile: kid\nparams: [1, 2]\n") == [
        "file.yaml:2:9: 'params' must map names to values, got a list"
    ]


def test_a_profile_parameter_name_must_be_a_plain_word(tmp_path: Path) -> None:
    assert problems(tmp_path, load_profile, "profile: kid\nparams:\n  rest s: 3\n") == [
        "file.yaml:3:3: parameter name 'rest s' is not a plain word (use letters, digits and _)"
    ]


@pytest.mark.parametrize("text", ["", "- kid\n"])
def test_a_profile_that_is_not_a_mapping_is_named(tmp_path: Path, text: str) -> None:
    assert problems(tmp_path, load_profile, text) == [
        "file.yaml:1:1: a profile is a mapping with 'profile:' and 'params:'"
    ]


def test_two_dialog_files_with_one_name_are_reported_with_both_files(tmp_path):
    from engine.blackboard.catalogue import default_catalogue
    from engine.dialogs import DialogLibrary
    from engine.files.problems import LoadError

    rule = 'rules:\n  - hear: ["hi"]\n    say: "Hello"\n'
    (tmp_path / "a.yaml").write_text("dialog: default\n" + rule)
    (tmp_path / "b.yaml").write_text("dialog: default\n" + rule)
    with pytest.raises(LoadError) as error:
        DialogLibrary.from_folder(tmp_path, default_catalogue())
    assert str(error.value).startswith(
        f"{tmp_path / 'b.yaml'}:1:1: two dialogs are named 'default' (also "
    )
