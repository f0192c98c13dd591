"""What someone trying to break the site's privacy tried, each now refused or kept safe:
words slipping past consent in quotes, a child saying a word that is also a tree's name,
sensor readings in a node's feedback, a key rotated under a running session, a report
written over a recording, a recording copied over another, an old site.db, a link sealed,
an export folder holding someone else's files, a recording inside the data folder, names
in consent.yaml."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.sealed_sqlite import connect_sealed
from engine.privacy.site import Site
from engine.privacy.site_data import SiteKey
from tests.privacy.conftest import Calendar

ROOT = Path(__file__).resolve().parents[2]
TRICKY = """\
duration_s: 6
events:
  - {at: 0.5, touch: {pad: middle_back}}
  - {at: 1.0, hear: "to"}
  - {at: 2.0, hear: "hug"}
  - {at: 3.0, hear: 'mum said "SECRETDQ is coming" and it''s today'}
  - {at: 4.0, hear: 'Zoë naïve\\path SECRETZ'}
"""


@pytest.fixture
def here(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


def record(tmp_path: Path, name: str, person: str, scenario: str = TRICKY) -> Path:
    story = tmp_path / "story.yaml"
    story.write_text(scenario)
    path = tmp_path / name
    args = ["run", "--fast", "--speech", "text", "--scenario", str(story), "--record", str(path)]
    assert main([*args, "--person", person]) == 0
    return path


def every_value(path: Path, key: SiteKey) -> list[str]:
    db = connect_sealed(path, key, read_only=True)
    try:
        return [
            str(value)
            for (table,) in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")
            for row in db.execute(f"SELECT * FROM {table}")
            for value in row
        ]
    finally:
        db.close()


def test_words_in_quotes_are_cut_and_a_word_that_is_also_a_name_breaks_nothing(
    here: None, tmp_path: Path, the_site_key: SiteKey
) -> None:
    values = every_value(record(tmp_path, "s.vest", "kid-1"), the_site_key)
    text = " ".join(values)
    assert "SECRETDQ" not in text and "SECRETZ" not in text
    assert "/sensors/touch/any" in values and "hug" in values  # a key and a tree's name
    assert "words not kept" in text


def test_without_consent_to_sensor_readings_no_node_tells_what_it_saw(
    here: None, tmp_path: Path, consenting, the_site_key: SiteKey
) -> None:
    consenting("kid-2", "speech_text")
    db = connect_sealed(record(tmp_path, "s.vest", "kid-2"), the_site_key, read_only=True)
    feedback = {text for (text,) in db.execute("SELECT feedback FROM statuses")}
    keys = {key for (key,) in db.execute("SELECT key FROM blackboard")}
    db.close()
    assert feedback == {""} and not any(key.startswith("/sensors/") for key in keys)


def test_the_key_is_not_rotated_while_another_vest_uses_the_site(
    site_data: Path, the_site_key: SiteKey, capsys: pytest.CaptureFixture[str]
) -> None:
    running = Site.open(site_data, clock=Calendar(1e9), who="a session")  # as vest run does
    try:
        assert main(["data", "rekey"]) == 1
        assert "another vest is using this site now" in capsys.readouterr().err
    finally:
        running.close()
    assert main(["data", "rekey"]) == 0


def test_a_report_is_never_written_over_a_recording_or_someone_s_file(
    here: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    first = record(tmp_path, "a.vest", "kid-a")
    second = record(tmp_path, "b.vest", "kid-b")
    kept = second.read_bytes()
    capsys.readouterr()
    assert main(["report", str(first), "-o", str(second)]) == 1
    assert "holds something else than a report" in capsys.readouterr().err
    assert second.read_bytes() == kept
    assert main(["report", str(first)]) == 0  # a.html, written ...
    assert main(["report", str(first)]) == 0  # ... and written again


def test_a_recording_copied_over_another_person_s_is_not_read_as_theirs(
    here: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    theirs = record(tmp_path, "x.vest", "kid-x")
    mine = record(tmp_path, "y.vest", "kid-y")
    shutil.copy(theirs, mine)
    capsys.readouterr()
    exported = tmp_path / "kid-y-export"
    for command in (
        ["replay", str(mine)],
        ["data", "export", "--person", "kid-y", "-o", str(exported)],
    ):
        assert main(command) == 1
        assert "holds a session of kid-x, but the site's index lists" in capsys.readouterr().err
    assert not exported.exists()


def test_a_site_db_of_an_earlier_vest_is_brought_up_to_date(
    site_data: Path, the_site_key: SiteKey, tmp_path: Path
) -> None:
    db = connect_sealed(site_data / "site.db", the_site_key)
    db.execute(
        "CREATE TABLE outputs (path TEXT PRIMARY KEY, person TEXT NOT NULL, kind TEXT NOT NULL,"
        " made REAL NOT NULL)"
    )
    db.execute("INSERT INTO outputs VALUES ('/r.html', 'kid-1', 'report', 1.0)")
    db.commit()
    db.close()
    site = Site.open(site_data, clock=Calendar(1e9), who="ana")
    site.output_written(tmp_path / "new.html", "kid-1", "report", [tmp_path / "s.vest"])
    assert [path.name for path, _ in site.records.outputs("kid-1")] == ["r.html", "new.html"]
    assert site.records.outputs_holding((tmp_path / "s.vest").resolve()) == [
        (tmp_path / "new.html").resolve()
    ]
    site.close()


def test_a_report_listed_by_the_vest_before_is_still_purged_with_its_recording(
    site_data: Path, the_site_key: SiteKey, tmp_path: Path
) -> None:
    """site.db of schema 1 named one recording per output (or none)."""
    site = Site.open(site_data, clock=Calendar(1e9), who="ana")
    site.close()
    db = connect_sealed(site_data / "site.db", the_site_key)
    db.execute("INSERT INTO outputs VALUES ('/r.html', 'kid-1', 'report', 1.0, '/a.vest')")
    db.execute("INSERT INTO outputs VALUES ('/p.html', 'kid-1', 'report', 1.0, '')")
    db.execute("PRAGMA user_version = 1")
    db.commit()
    db.close()
    site = Site.open(site_data, clock=Calendar(1e9), who="ana")
    assert site.records.outputs_holding(Path("/a.vest")) == [Path("/r.html")]
    assert len(site.records.outputs("kid-1")) == 2
    site.close()


def test_sealing_a_link_or_a_recording_that_names_a_person_is_done_safely(
    tmp_path: Path, site_data: Path, capsys: pytest.CaptureFixture[str], the_site_key: SiteKey
) -> None:
    original = tmp_path / "old.db"
    shutil.copy(ROOT / "tests/recordings/unplug_touch.format1.db", original)
    link = tmp_path / "link.db"
    link.symlink_to(original)
    assert main(["data", "seal", str(link)]) == 1
    assert "a link; name the file itself" in capsys.readouterr().err
    import sqlite3

    with sqlite3.connect(original) as db:  # made by an earlier vest that took any name
        db.execute("INSERT OR REPLACE INTO meta VALUES ('person', 'Alice Smith')")
        db.execute("INSERT OR REPLACE INTO meta VALUES ('started', '-1e308')")
    assert main(["data", "seal", str(original)]) == 0
    err = capsys.readouterr().err
    assert "names its person 'Alice Smith', not a pseudonym" in err
    assert "no start time it could have had" in err
    assert main(["data", "list"]) == 0 and main(["replay", str(original)]) == 0


def test_an_erasure_removes_what_the_export_wrote_and_leaves_someone_else_s_notes(
    here: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    record(tmp_path, "s.vest", "kid-5")
    folder = tmp_path / "export"
    assert main(["data", "export", "--person", "kid-5", "-o", str(folder)]) == 0
    (folder / "notes.txt").write_text("the teacher's notes")
    assert main(["data", "erase", "--person", "kid-5", "--yes"]) == 0
    assert sorted(p.name for p in folder.iterdir()) == ["notes.txt"]


def test_no_recording_is_made_anywhere_inside_the_data_folder(
    here: None, site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inside = site_data / "sessions" / "s.vest"
    inside.parent.mkdir(parents=True)
    assert main(["run", "--fast", "--speech", "text", "--record", str(inside)]) == 1
    assert "is in the site's data folder, with its key" in capsys.readouterr().err


def test_consent_yaml_takes_pseudonyms_and_roles_never_names(
    site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site_data.mkdir(parents=True, mode=0o755)
    (site_data / "consent.yaml").write_text(
        '"Alice Smith":\n  given_by: guardian\n  given_on: 2026-01-01\n  covers: [sensors]\n'
        "kid-9:\n  given_by: Mrs Smith\n  given_on: 2026-01-01\n  covers: [sensors]\n"
    )
    os.chmod(site_data / "consent.yaml", 0o644)
    assert main(["data", "consent"]) == 1
    err = capsys.readouterr().err
    assert "consent.yaml:1:1: 'Alice Smith' is not a pseudonym" in err
    assert "consent.yaml:6:13: given_by: who gave consent, as a role" in err
    assert (
        site_data.stat().st_mode & 0o777,
        (site_data / "consent.yaml").stat().st_mode & 0o777,
    ) == (
        0o700,
        0o600,
    )


def test_without_consent_every_event_of_a_busy_session_is_still_recorded(
    here: None, tmp_path: Path, caplog: pytest.LogCaptureFixture, the_site_key: SiteKey
) -> None:
    """Turns (a tree waiting for the speaker, yielding it) after words were heard: the
    recording loses none of them when words are cut out of it (a reader that fails is
    logged, and its events lost)."""
    path = record(tmp_path, "busy.vest", "kid-7")
    assert "failed on" not in caplog.text
    db = connect_sealed(path, the_site_key, read_only=True)
    turns = db.execute("SELECT count(*) FROM events WHERE kind = 'turn'").fetchone()[0]
    db.close()
    assert turns > 0
