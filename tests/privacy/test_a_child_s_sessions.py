"""A clinic records a child's sessions under a pseudonym: the files are sealed with the
site's key, only what the guardian consented to is kept, and the site can list, report,
export and erase what it holds, with an audit trail of who did what."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.sealed_sqlite import connect_sealed
from engine.privacy.site_data import SiteKey

ROOT = Path(__file__).resolve().parents[2]
STORY = """\
duration_s: 8
events:
  - {at: 1.0, squeeze: {left_n: 9, right_n: 9, seconds: 1.0}}
  - {at: 3.0, hear: "my name is Lina and I like dogs"}
  - {at: 5.0, hear: "what's your name?"}
"""


@pytest.fixture
def story(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(ROOT)
    path = tmp_path / "story.yaml"
    path.write_text(STORY)
    return path


def run(story: Path, record: Path, *person: str) -> None:
    args = ["run", "--fast", "--speech", "text", "--scenario", str(story)]
    assert main([*args, "--record", str(record), *(["--person", *person] if person else [])]) == 0


def test_without_consent_the_words_are_not_kept_but_the_robot_still_answers(
    story: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], the_site_key: SiteKey
) -> None:
    record = tmp_path / "kid-17.vest"
    run(story, record, "kid-17")
    out, err = capsys.readouterr()
    assert "kid-17: no consent record: keeps sensor readings" in err
    assert 'dialog         says "My name is' in out  # it answered what it heard
    db = connect_sealed(record, the_site_key, read_only=True)
    keys = {key for (key,) in db.execute("SELECT key FROM blackboard")}
    world = [
        d
        for (d,) in db.execute(
            "SELECT json_extract(data, '$.description') FROM events "
            "WHERE json_extract(data, '$.scenario_event') = 'hear'"
        )
    ]
    left_out = db.execute("SELECT value FROM meta WHERE key = 'left_out'").fetchone()[0]
    everything = " ".join(  # every value of every row of every table
        str(value)
        for (table,) in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")
        for row in db.execute(f"SELECT * FROM {table}")
        for value in row
    )
    db.close()
    for word in ("Lina", "dogs", "what's your name"):  # not in a node's feedback either
        assert word.lower() not in everything.lower(), word
    assert "/speech/heard" not in keys and "/sensors/force/left_n" in keys
    assert world and all("Lina" not in d and "words not kept" in d for d in world)
    assert left_out == "speech as text, audio, camera frames, telemetry to the cloud"
    assert main(["replay", str(record)]) == 0
    assert "not kept (no consent): speech as text" in capsys.readouterr().out


def test_with_consent_to_speech_as_text_the_words_are_kept(
    story: Path, tmp_path: Path, consenting, the_site_key: SiteKey
) -> None:
    consenting("kid-17", "sensors", "speech_text")
    record = tmp_path / "kid-17.vest"
    run(story, record, "kid-17")
    db = connect_sealed(record, the_site_key, read_only=True)
    heard = [v for (v,) in db.execute("SELECT value FROM blackboard WHERE key = '/speech/heard'")]
    db.close()
    assert any("Lina" in value for value in heard)


def test_a_recording_holds_no_header_and_no_phrase_and_another_machine_cannot_read_it(
    story: Path,
    tmp_path: Path,
    consenting,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    consenting("kid-17", "sensors", "speech_text")
    record = tmp_path / "kid-17.vest"
    run(story, record, "kid-17")
    raw = record.read_bytes()
    assert not raw.startswith(b"SQLite format 3")
    # phrases of six bytes or more: random ciphertext holds a given 3-byte string (the
    # tree name "hug") once in 16 MB, so this 120 kB recording did in about one run in 140
    for phrase in (b"Lina and I like dogs", b"kid-17", b"My name is", b"I love hugs!"):
        assert phrase not in raw
    elsewhere = tmp_path / "another-machine"
    shutil.copy(record, elsewhere.with_suffix(".vest"))
    monkeypatch.setenv("VEST_DATA", str(elsewhere / "data"))
    capsys.readouterr()
    for command in (["replay", str(elsewhere.with_suffix(".vest"))], ["report", str(record)]):
        assert main(command) == 1
        err = capsys.readouterr().err
        assert "no site key here" in err and "Traceback" not in err and len(err.splitlines()) == 1
    monkeypatch.setenv("VEST_DATA", str(tmp_path / "another-site"))
    main(["data", "list"])  # that machine's own site, with its own key
    assert main(["replay", str(record)]) == 1
    assert "cannot be read with this site's key: recorded at another site" in (
        capsys.readouterr().err
    )


def test_a_changed_or_cut_recording_is_named_never_read(
    story: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    record = tmp_path / "s.vest"
    run(story, record)
    whole = record.read_bytes()
    changed = bytearray(whole)
    changed[5000] ^= 0x01
    record.write_bytes(bytes(changed))
    capsys.readouterr()
    assert main(["replay", str(record)]) == 1
    assert "changed or damaged since it was written" in capsys.readouterr().err
    record.write_bytes(whole[:-1000])
    assert main(["replay", str(record)]) == 1
    assert "s.vest: not a vest recording, or one cut short" in capsys.readouterr().err


def test_the_site_lists_each_person_s_sessions_and_reports_their_progress(
    story: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], consenting
) -> None:
    consenting("kid-17", "sensors", "speech_text")
    for name in ("first", "second"):
        run(story, tmp_path / f"{name}.vest", "kid-17")
    run(story, tmp_path / "someone-else.vest", "kid-4")
    capsys.readouterr()
    assert main(["data", "list", "--person", "kid-17", "--json"]) == 0
    listed = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [Path(s["file"]).name for s in listed] == ["first.vest", "second.vest"]
    assert all(s["length_s"] == pytest.approx(8.0, abs=0.2) for s in listed)
    assert listed[0]["kept"] == ["sensors", "speech_text"] or set(listed[0]["kept"]) == {
        "sensors",
        "speech_text",
    }
    progress = tmp_path / "kid-17.html"
    assert main(["report", "--person", "kid-17", "-o", str(progress)]) == 0
    page = progress.read_text()  # a scenario played the child's part: no real session
    assert "0 sessions" in page and "2 simulated sessions (on the simulated vest: no child)" in page
    args = ["report", "--person", "kid-17", "-o", str(progress), "--with-simulated"]
    assert main(args) == 0
    page = progress.read_text()
    assert "Progress of kid-17" in page and "2 sessions" in page and "dialog" in page
    assert page.count(" (simulated)</td>") == 2
    assert "someone-else" not in page


def test_a_consent_file_with_mistakes_stops_the_run_naming_each_place(
    story: Path, site_data: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    site_data.mkdir(parents=True)
    (site_data / "consent.yaml").write_text(
        "kid-17:\n  given_by: guardian\n  given_on: 2026-13-01\n  covers: [sensors, speach_text]\n"
    )
    assert main(["run", "--fast", "--speech", "text", "--record", str(tmp_path / "s.vest")]) == 1
    err = capsys.readouterr().err
    assert "consent.yaml:3:13: given_on: a day as YYYY-MM-DD" in err
    assert "consent.yaml:4:21: covers: 'speach_text' is not something vest keeps" in err
    assert "did you mean 'speech_text'" in err
    assert not (tmp_path / "s.vest").exists()


def test_consent_that_has_ended_keeps_only_sensor_readings(
    story: Path, tmp_path: Path, site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site_data.mkdir(parents=True)
    (site_data / "consent.yaml").write_text(
        "kid-17:\n  given_by: guardian\n  given_on: 2020-01-01\n  until: 2020-12-31\n"
        "  covers: [sensors, speech_text, cloud_telemetry]\n"
    )
    assert main(["data", "consent", "kid-17"]) == 0
    said = capsys.readouterr().out
    assert "kid-17: their consent ended on 2020-12-31 (renew it with vest data consent)" in said
    assert "keeps sensor readings (and the robot's actions)" in said
