"""`vest report`: a recorded session as the therapist reads it."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.site_data import SiteKey
from engine.recording.moments import outages
from engine.recording.replay import Recording
from engine.recording.report import person_moments
from engine.recording.report_page import printable

ROOT = Path(__file__).resolve().parents[1]


def record(tmp_path: Path, scenario: str, capsys, monkeypatch) -> Path:
    monkeypatch.chdir(ROOT)
    path = tmp_path / "session.db"
    args = ["run", "--fast", "--speech", "text", "--scenario", scenario, "--record", str(path)]
    assert main(args) == 0
    capsys.readouterr()
    return path


def test_each_thing_the_person_did_is_paired_with_the_robot_s_answer(
    tmp_path: Path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    recording = Recording.open(
        record(tmp_path, "examples/scenarios/demo.yaml", capsys, monkeypatch), the_site_key
    )
    moments = person_moments(recording)
    did = [(round(m.at_s, 1), m.answer.tree if m.answer else None) for m in moments]
    assert did[:3] == [(1.0, "touch_thanks"), (3.0, "hug"), (6.0, "wave_greeting")]
    before_the_game = [m for m in moments if m.at_s < 21.0]
    assert all(m.response_s is not None and m.response_s >= 0 for m in before_the_game)


def test_the_demo_s_report_lists_the_scenario_s_press_as_the_scenario_s(
    tmp_path: Path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    path = record(tmp_path, "examples/scenarios/demo.yaml", capsys, monkeypatch)
    moments = person_moments(Recording.open(path, the_site_key))
    [press] = [m for m in moments if m.who == "the scenario"]  # scripted: not the therapist
    assert (round(press.at_s, 1), press.did) == (7.0, "pressed the button \u201cWell done\u201d")
    assert press.answer is not None and press.answer.tree == "buttons"
    assert main(["report", str(path)]) == 0
    page = path.with_suffix(".html").read_text()
    assert "<td>the scenario</td><td>pressed the button \u201cWell done\u201d</td>" in page


def test_a_device_that_dropped_out_is_listed_with_how_long(
    tmp_path: Path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    path = record(tmp_path, "examples/scenarios/unplug_touch.yaml", capsys, monkeypatch)
    [(since, back)] = [
        (s, b) for d, s, b in outages(Recording.open(path, the_site_key)) if d == "touch"
    ]
    assert 2.0 <= since < 2.5 and back is not None and 6.0 <= back < 8.5


def test_vest_report_writes_one_printable_page_with_its_pictures_inside(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    path = record(tmp_path, "examples/scenarios/unplug_touch.yaml", capsys, monkeypatch)
    assert main(["report", str(path)]) == 0
    page = path.with_suffix(".html").read_text()
    assert f"report: {path.with_suffix('.html')}" in capsys.readouterr().out
    assert "What the person did, and how the robot answered" in page
    assert "hug: said \u201cI love hugs!\u201d" in page or "hug: lit its face pink" in page
    assert "<td>touch</td>" in page  # it dropped out
    assert page.count("<svg") == 2  # squeeze and touch; nobody came in front of it
    assert "@page { size: A4" in page
    assert "src=" not in page and "href=" not in page  # nothing outside the file


def test_the_answer_to_a_touch_the_robot_could_not_feel_is_not_the_hug_after_it(
    tmp_path: Path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    path = record(tmp_path, "examples/scenarios/unplug_touch.yaml", capsys, monkeypatch)
    moments = {round(m.at_s): m for m in person_moments(Recording.open(path, the_site_key))}
    assert moments[3].answer is None  # pad 5 touched while the touch sensor was unplugged
    assert moments[4].answer is not None and moments[4].answer.tree == "hug"
    assert [a.action for a in moments[4].answers] == ["led", "say"]


def test_a_report_that_cannot_be_written_is_said_in_one_line(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    path = record(tmp_path, "examples/scenarios/unplug_touch.yaml", capsys, monkeypatch)
    assert main(["report", str(path), "-o", str(tmp_path / "no" / "r.html")]) == 1
    assert "r.html: cannot write the report" in capsys.readouterr().err
    fifo = tmp_path / "fifo.html"
    os.mkfifo(fifo)  # nobody reads it: writing would wait for ever
    assert main(["report", str(path), "-o", str(fifo)]) == 1
    assert "fifo.html: cannot write the report (is not a regular file" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["gone.db"])
def test_a_missing_recording_is_named(tmp_path: Path, capsys, name: str) -> None:
    assert main(["report", str(tmp_path / name)]) == 1
    assert f"{name}: no such recording" in capsys.readouterr().err


SUPERVISED = """\
duration_s: 12
events:
  - {at: 1.0, touch: {pad: middle_back, seconds: 0.3}}
  - {at: 3.0, press: Pause}
  - {at: 4.0, touch: {pad: middle_back, seconds: 0.3}}
  - {at: 5.0, press: Resume}
  - {at: 6.0, squeeze: {left_n: 6, right_n: 6, seconds: 2}}
  - {at: 9.0, press: Stop everything}
  - {at: 10.0, cloud: {type: say, args: {text: "hello from the cloud"}}}
"""


@pytest.fixture
def supervised(tmp_path: Path, capsys, monkeypatch) -> Path:
    """A session with the therapist's controls pressed, as a supervisor would read it."""
    scenario = tmp_path / "supervised.yaml"
    scenario.write_text(SUPERVISED)
    path = record(tmp_path, str(scenario), capsys, monkeypatch)
    note = "Sam was calm today.\n\nTry the hug game next time: <b>slowly</b>."
    assert main(["report", str(path), "--note", note]) == 0
    capsys.readouterr()
    return path.with_suffix(".html")


def test_a_press_of_pause_resume_or_stop_is_what_it_did_never_no_answer(
    supervised: Path,
) -> None:
    page = supervised.read_text()
    assert "pressed the button \u201cPause\u201d</td><td>paused the behaviours</td>" in page
    assert "pressed the button \u201cResume\u201d</td><td>resumed the behaviours</td>" in page
    assert "\u201cStop everything\u201d</td><td>stopped everything and paused" in page
    # the pat while paused was not answered, and the report says why
    assert "no answer: the behaviours were paused" in page
    assert "the buttons paused, resumed or stopped the behaviours 3 times (a row each)" in page


def test_the_report_says_what_was_done_in_words_by_kind_and_per_minute(supervised: Path) -> None:
    page = supervised.read_text()
    said = "<td>the operator</td><td>sends say: text &quot;hello from the cloud&quot;</td>"
    assert said in page  # in words, not a Python dict
    assert "{&#x27;text&#x27;" not in page
    # 12 s: 2 touches are 10 a minute, 3 presses 15
    person = "<td>the person</td><td>touches</td><td class='num'>2</td><td class='num'>10.0</td>"
    presses = "<td>the scenario</td><td>button presses</td><td class='num'>3</td>"
    assert person in page and presses in page  # the presses apart from the person's
    assert page.index(person) < page.index(presses)
    assert "<td>hug</td><td>When both sides are squeezed at once (a hug)" in page  # described


def test_the_therapist_s_note_is_in_the_report_as_written(supervised: Path) -> None:
    page = supervised.read_text()
    assert "<h2>The therapist's note</h2><p>Sam was calm today.</p>" in page
    assert "<p>Try the hug game next time: &lt;b&gt;slowly&lt;/b&gt;.</p>" in page  # as text


def test_a_scripted_session_s_report_says_it_was_simulated(supervised: Path) -> None:
    assert "A simulated session: on the simulated vest, a scenario or the buttons page played" in (
        supervised.read_text()
    )


@pytest.mark.parametrize(
    ("args", "why"),
    [
        (["--note", "a\x07bell"], "--note: holds control characters"),
        (["--note", "a\x85next line"], "--note: holds control characters"),
        (["--note", "caf\udce9"], "--note: is not UTF-8 text"),
        (["--note", "x" * 20_001], "a note has at most 20,000"),
        (["--person", "kid-17", "--note", "hi"], "--note goes with one session's FILE"),
    ],
    ids=["control", "c1-control", "not-utf8", "long", "progress"],
)
def test_a_note_vest_cannot_put_in_a_report_is_refused_in_words(
    tmp_path: Path, capsys, args: list[str], why: str
) -> None:
    given = [str(tmp_path / "s.vest")] if args[0] == "--note" else []
    try:
        assert main(["report", *given, *args]) == 2
    except SystemExit as refused:  # refused by the option itself, as argparse does
        assert refused.code == 2
    assert why in capsys.readouterr().err


LONG_HUG = """\
name: long_hug
rate_hz: 20
priority: 49
wait_for_turn_s: 3
root:
  Sequence:
    - HeldFor:
        seconds: 3
        child:
          Check: {key: /sensors/force/left_n, above: 3}
    - Say: {text: "What a long hug!"}
"""


def test_an_answer_that_comes_after_a_hold_is_on_the_hug_s_row_with_its_delay(
    tmp_path: Path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    monkeypatch.chdir(ROOT)
    trees = tmp_path / "trees"
    shutil.copytree(ROOT / "trees", trees)
    (trees / "long_hug.yaml").write_text(LONG_HUG)
    scenario = tmp_path / "hug.yaml"
    scenario.write_text(
        "duration_s: 10\nevents:\n  - {at: 1.0, squeeze: {left_n: 5, right_n: 5, seconds: 4}}\n"
    )
    path = tmp_path / "s.vest"
    args = ["run", "--fast", "--speech", "text", "--trees", str(trees), "--scenario", str(scenario)]
    assert main([*args, "--record", str(path)]) == 0
    capsys.readouterr()
    [hug] = person_moments(Recording.open(path, the_site_key))
    assert list(hug.by_tree) == ["hug", "long_hug"]  # at once, then after the hold
    assert main(["report", str(path)]) == 0
    page = path.with_suffix(".html").read_text()
    assert "long_hug: said \u201cWhat a long hug!\u201d (3.0" in page
    assert "<td>long_hug</td><td></td><td class='num'>1</td>" in page  # times it answered


def test_a_control_character_in_a_recording_s_text_never_reaches_the_page() -> None:
    # a hand-made or damaged recording may hold a NUL or a terminal's colour codes in a label
    assert printable("<td>a\x00b\x1b[31m\x85c\nd\te</td>") == (
        "<td>a\ufffdb\ufffd[31m\ufffdc\nd\te</td>"
    )


TWO_SQUEEZES = """\
name: two_squeezes
rate_hz: 20
root:
  Sequence:
    - TimesWithin:
        times: 2
        within_s: 4
        child:
          Check: {key: /sensors/force/left_n, above: 2}
    - Say: {text: "Two squeezes!"}
"""


def test_the_first_of_two_squeezes_is_counted_not_left_unanswered(
    tmp_path: Path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    # "squeezed twice": the robot is right to say nothing at the first squeeze
    monkeypatch.chdir(ROOT)
    tree = tmp_path / "two_squeezes.yaml"
    tree.write_text(TWO_SQUEEZES)
    scenario = tmp_path / "twice.yaml"
    scenario.write_text(
        "duration_s: 8\nevents:\n"
        "  - {at: 1.0, squeeze: {left_n: 3, seconds: 0.5}}\n"
        "  - {at: 3.0, squeeze: {left_n: 3, seconds: 0.5}}\n"
    )
    path = tmp_path / "s.vest"
    args = ["run", "--fast", "--speech", "text", "--trees", str(tree), "--scenario", str(scenario)]
    assert main([*args, "--record", str(path)]) == 0
    first, second = person_moments(Recording.open(path, the_site_key))
    assert first.counted_by == "two_squeezes" and first.answer is None
    assert second.answer is not None and second.answer.args["text"] == "Two squeezes!"
    assert main(["report", str(path)]) == 0
    page = path.with_suffix(".html").read_text()
    assert "counted by two_squeezes, which answers the next one" in page
    assert "no answer" not in page
    assert "nothing was said to it" in page  # not "everything it heard matched a rule"
