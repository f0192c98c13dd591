"""One account of every session: the terminal timeline, --json, the recording, the live
view and the report all read the one session event stream, so none of them tells a
different story.

The story: the demo, recorded, with a therapist's press, a tree cut short by a higher one,
and a question the robot did not understand; then read back as a replay and a report.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.cli import main
from engine.clock import VirtualClock
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording
from engine.recording.report import not_understood, person_moments, report_html
from engine.recording.session_file import FORMAT_VERSION
from engine.recording.told import told_events
from engine.services.telemetry import TelemetrySnapshot
from engine.session.blackboard_news import ChangedKeys
from engine.session.events import (
    ActionEnded,
    ButtonPressed,
    KeyChanged,
    SafetyAction,
    TurnTaken,
)
from engine.session.json_values import json_text
from engine.session.sentences import event_line
from engine.session.stream import SessionStream
from engine.view.hub import ViewHub

ROOT = Path(__file__).resolve().parents[1]
STORY = """\
duration_s: 12
events:
  - {at: 1.0, press: Hello}
  - {at: 2.0, hear: "what is the weather like on the moon"}
  - {at: 4.0, hear: "what's your name?"}
  - {at: 4.4, cloud: {type: say, args: {text: "hello from the cloud"}}}
"""


@pytest.fixture
def session(tmp_path: Path, capsys, monkeypatch, consenting) -> tuple[Path, str]:
    """The story run on a virtual clock, recorded, with --person, whose guardian consented
    to keeping what they said as text; (recording, timeline)."""
    consenting("kid-17", "sensors", "speech_text")
    monkeypatch.chdir(ROOT)
    scenario = tmp_path / "story.yaml"
    scenario.write_text(STORY)
    recording = tmp_path / "kid-17.db"
    args = ["run", "--fast", "--speech", "text", "--scenario", str(scenario)]
    args += ["--record", str(recording), "--person", "kid-17"]
    assert main(args) == 0
    return recording, capsys.readouterr().out.split("\n\n")[0]


def test_the_recording_tells_what_the_terminal_told_line_for_line(
    session, the_site_key: SiteKey
) -> None:
    path, timeline = session
    printed = [line.split(None, 2)[1:] for line in timeline.splitlines()[1:]]
    told = [
        list(line)
        for e in told_events(Recording.open(path, the_site_key))
        if (line := event_line(e))
    ]
    assert [[who, what] for who, what in printed] == told


def test_an_utterance_cut_short_is_told_as_cut_in_the_timeline_the_json_and_the_record(
    session, tmp_path, capsys, the_site_key: SiteKey
) -> None:
    path, timeline = session
    sorry = "Sorry, I did not understand."
    assert f'dialog         cut short: says "{sorry}" (iot_command interrupted it)' in timeline
    [cut] = [
        e
        for e in told_events(Recording.open(path, the_site_key))
        if isinstance(e, ActionEnded) and e.outcome != "done"
    ]
    assert (cut.tree, cut.outcome, cut.why) == ("dialog", "cut", "iot_command interrupted it")
    story = str(tmp_path / "story.yaml")
    assert main(["run", "--fast", "--speech", "text", "--json", "--scenario", story]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    [outcome] = [line for line in lines if line["event"] == "outcome"]
    assert outcome["outcome"] == "cut" and outcome["args"]["text"] == sorry
    assert outcome["started"] < outcome["t"]


def test_the_report_lists_the_therapist_s_press_and_a_sentence_not_understood_once(
    session,
    the_site_key: SiteKey,
) -> None:
    path, _ = session
    recording = Recording.open(path, the_site_key)
    moments = person_moments(recording)
    press = next(m for m in moments if m.who == "the scenario")
    assert press.did == "pressed the button \u201cHello\u201d"
    assert press.answer is not None and press.answer.tree == "buttons"
    moon = next(m for m in moments if "moon" in m.did)
    assert moon.not_understood == "what is the weather like on the moon"
    assert moon.answer is not None and moon.answer.args["text"] == "Sorry, I did not understand."
    [missed] = not_understood(recording)
    assert (missed.t_s, missed.text) == (pytest.approx(2.0, abs=0.1), moon.not_understood)
    assert not missed.asked and not missed.reprompt  # the dialog had nothing like it
    page = report_html(recording)
    assert "did not understand \u201cwhat is the weather like on the moon\u201d" in page
    assert "kid-17" in page and "UTC" in page  # whose session, and when
    assert "no answer" not in page


def test_the_live_view_tells_turns_safety_and_presses_in_words() -> None:
    clock = VirtualClock()
    stream = SessionStream(clock)
    hub = ViewHub(clock)
    stream.subscribe(hub)
    stream.publish(ButtonPressed(1.0, "Well done", "page"))
    stream.publish(TurnTaken(1.0, "hug", "yields", "speaker", "buttons", "saying 'Hi'"))
    stream.publish(
        SafetyAction(2.0, "stopped", "left_arm", "still_within_mm", ("range_center",), "why")
    )
    happened = hub.snapshot()["happened"]
    assert [(h["who"], h["what"], h["tone"]) for h in happened] == [
        ("therapist", "presses the button 'Well done'", "therapist"),
        ("hug", "yields the speaker to buttons: not saying 'Hi'", "turn"),
        ("safety", "stops left_arm where it is: why", "safety"),
    ]


def test_a_recording_of_the_first_format_still_replays_and_reports(
    tmp_path, the_site_key: SiteKey
) -> None:
    kept = Path(__file__).parent / "recordings" / "unplug_touch.format1.db"
    recording = Recording.open(kept, the_site_key)
    assert recording.format == 1
    told = [event_line(e) for e in told_events(recording)]
    assert ("touch_thanks", 'says "Thank you"') in told
    assert ("vest", "touch is offline") in told
    assert "Session report" in report_html(recording)


def test_a_recording_of_the_second_format_tells_what_a_new_one_tells(
    tmp_path, capsys, monkeypatch, the_site_key: SiteKey
) -> None:
    # the demo recorded by vest when recordings kept actions, the scenario and the rest
    # in tables of their own (format 2), and the same demo recorded now (the events)
    kept = Path(__file__).parent / "recordings" / "demo.format2.db"
    monkeypatch.chdir(ROOT)
    now = tmp_path / "demo.db"
    demo = ROOT / "examples" / "scenarios" / "demo.yaml"
    then = [line for line in demo.read_text().splitlines() if "at: 27.6" not in line]
    scenario = tmp_path / "demo_then.yaml"  # the demo as it was: no one spoke over the robot
    scenario.write_text(
        "\n".join(then)
        .replace("wav: voices/", f"wav: {demo.parent}/voices/")
        .replace("image: ../", f"image: {demo.parent}/../"),
        encoding="utf-8",
    )
    args = ["run", "--fast", "--speech", "text", "--scenario", str(scenario)]
    assert main([*args, "--record", str(now)]) == 0
    capsys.readouterr()
    earlier, later = Recording.open(kept, the_site_key), Recording.open(now, the_site_key)
    assert (earlier.format, later.format) == (2, FORMAT_VERSION)
    # a node's plain words are kept now (a replay shows them as the live view did)
    [hug] = [tree for tree in later.trees if tree.name == "hug"]
    assert "force on the left side pad above 3 N?" in [node.words for node in hug.nodes]
    assert {node.words for tree in earlier.trees for node in tree.nodes} == {""}
    told = [[event_line(e) for e in told_events(r)] for r in (earlier, later)]
    # an operator's command is now told in words; a recording keeps the words it was told in
    old_words = ("world", "operator sends say {'text': 'hello from the cloud'}")
    new_words = ("world", 'operator sends say: text "hello from the cloud"')
    told[0] = [new_words if line == old_words else line for line in told[0]]
    told[0] = [
        ("world", 'operator sends read: sensor "temperature"')
        if line == ("world", "operator sends read {'sensor': 'temperature'}")
        else line
        for line in told[0]
    ]
    assert [line for line in told[0] if line] == [line for line in told[1] if line]
    assert [
        [(a.at_s, a.tree, a.action, a.args, a.outcome) for a in r.actions()]
        for r in (earlier, later)
    ] == [[(a.at_s, a.tree, a.action, a.args, a.outcome) for a in later.actions()]] * 2
    worlds = [
        [(at, kind, kind == "cloud" or d) for at, kind, d in r.world()] for r in (earlier, later)
    ]
    assert worlds[0] == worlds[1] and earlier.moments() == later.moments()
    assert "Session report" in report_html(earlier)


def test_a_reading_that_cannot_be_trusted_is_null_on_every_path() -> None:
    # a force pad that fails reads NaN (the worst case); JSON has no NaN
    key = "/sensors/force/left_n"
    text, _ = ChangedKeys(default_catalogue()).news(key, float("nan")) or ("", False)
    assert text == "null"  # the live view's and the recording's text
    changed = KeyChanged(1.0, key, float("nan"), text, False, "force_pads")
    telemetry = TelemetrySnapshot()
    telemetry.on_event(changed)
    assert telemetry.take() == {key: None}  # what the cloud is sent
    assert json.loads(json_text({"value": changed.value})) == {"value": None}  # --json, MCAP
