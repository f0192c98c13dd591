"""What a site holds is kept as long as it said and no longer, handed over or erased on a
family's request, under a new key when the old one may have leaked, and every step of it
is in an append-only audit trail."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from engine.cli import main
from engine.errors import ConfigError
from engine.privacy.sealed_sqlite import connect_sealed
from engine.privacy.site import Site
from tests.privacy.conftest import Calendar

ROOT = Path(__file__).resolve().parents[2]
DAY_S = 86_400.0


@pytest.fixture
def recorded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> list[Path]:
    """Two sessions of kid-17 (the guardian consented to speech as text), one of kid-4."""
    monkeypatch.chdir(ROOT)
    assert main(["data", "consent", "kid-17", "--given-by", "guardian", "--covers",
                 "sensors,speech_text"]) == 0  # fmt: skip
    made = []
    for name, person in (("a", "kid-17"), ("b", "kid-17"), ("c", "kid-4")):
        path = tmp_path / f"{name}.vest"
        args = ["run", "--fast", "--speech", "text", "--duration", "4", "--record", str(path)]
        assert main([*args, "--person", person]) == 0
        made.append(path)
    assert main(["report", str(made[0]), "-o", str(tmp_path / "a.html")]) == 0
    capsys.readouterr()
    return made


def test_an_erasure_asks_then_leaves_nothing_naming_the_person_but_the_audit_trail(
    recorded: list[Path], tmp_path: Path, site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    exported = tmp_path / "kid-17-export"
    assert main(["data", "export", "--person", "kid-17", "-o", str(exported)]) == 0
    sessions = sorted((exported / "sessions").glob("*.json"))
    assert len(sessions) == 2 and len(list((exported / "reports").glob("*.html"))) == 2
    assert json.loads((exported / "consent.json").read_text())["given_by"] == "guardian"
    assert json.loads(sessions[0].read_text())["meta"]
    capsys.readouterr()
    assert main(["data", "erase", "--person", "kid-17"]) == 2  # no terminal to ask on
    assert "cannot be undone: add --yes to confirm" in capsys.readouterr().err
    assert recorded[0].exists()
    assert main(["data", "erase", "--person", "kid-17", "--yes"]) == 0
    assert not recorded[0].exists() and not recorded[1].exists() and recorded[2].exists()
    assert not (tmp_path / "a.html").exists() and not exported.exists()
    assert "kid-17" not in (site_data / "consent.yaml").read_text()
    capsys.readouterr()
    assert main(["data", "list", "--json"]) == 0
    assert [json.loads(line)["person"] for line in capsys.readouterr().out.splitlines()] == [
        "kid-4"
    ]
    assert main(["data", "audit", "--person", "kid-17"]) == 0
    assert capsys.readouterr().out.splitlines()[-1].endswith("erase kid-17: 4 files removed")


def test_an_erasure_cut_off_half_way_finishes_on_the_next_run(
    recorded: list[Path], site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site = Site.open(site_data, clock=Calendar(1e9), who="ana")
    site.records.begin_erasing("kid-17", 1e9)  # marked, then the power went
    recorded[0].unlink()  # one file removed before it
    site.close()
    assert main(["data", "list"]) == 0
    captured = capsys.readouterr()
    assert "finished erasing kid-17 (cut off earlier)" in captured.err
    assert "kid-17" not in captured.out and not recorded[1].exists()


def test_the_audit_trail_is_append_only_and_a_changed_line_is_found(
    recorded: list[Path], site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["replay", str(recorded[1])]) == 0
    capsys.readouterr()
    assert main(["data", "audit", "--json"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    actions = [(line["action"], line["person"]) for line in lines]
    assert actions[:4] == [
        ("consent", "kid-17"),
        ("record", "kid-17"),
        ("record", "kid-17"),
        ("record", "kid-4"),
    ]
    assert ("replay", "kid-17") in actions and ("report written", "kid-17") in actions
    site = Site.open(site_data, clock=Calendar(1e9), who="ana")
    db = site.records._connection
    with pytest.raises(Exception, match="append-only"):
        db.execute("UPDATE audit SET who = 'nobody' WHERE seq = 2")
    db.execute("DROP TRIGGER audit_is_not_changed")  # someone with the key, and SQL
    db.execute("UPDATE audit SET who = 'nobody' WHERE seq = 2")
    db.commit()
    site.close()
    assert main(["data", "audit"]) == 1
    assert "line 2 and after were changed after they were written" in capsys.readouterr().err


def test_sessions_older_than_the_site_keeps_them_are_purged(
    recorded: list[Path], site_data: Path
) -> None:
    (site_data / "site.yaml").write_text("keep_sessions_days: 30\n")
    started = Site.open(site_data, clock=Calendar(0), who="ana").records.sessions()[0].started
    site = Site.open(site_data, clock=Calendar(started + 29 * DAY_S), who="ana")
    assert site.purge().sessions == []
    report = recorded[0].with_suffix(".html")  # a.vest's report, in the clear
    assert report.exists() and report.stat().st_mode & 0o077 == 0  # its owner's alone
    site.clock = Calendar(started + 31 * DAY_S)
    purged = site.purge()
    assert sorted(entry.path.name for entry in purged.sessions) == ["a.vest", "b.vest", "c.vest"]
    assert not any(path.exists() for path in recorded) and not report.exists()
    assert site.records.sessions() == [] and purged.not_removed == []
    assert [line.action for line in site.records.audit_lines()][-4:] == ["purge"] * 4
    site.close()


def test_a_purge_removes_every_copy_that_held_a_purged_session(
    recorded: list[Path],
    site_data: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """An export and a progress report hold every session of the person: past the site's
    keeping, they go with the sessions; a progress report is never left in the current
    folder, where `git add -A` would commit a child's report."""
    monkeypatch.chdir(tmp_path)
    assert main(["report", "--person", "kid-17"]) == 0
    progress = site_data / "reports" / "kid-17-progress.html"
    assert progress.is_file() and not list(tmp_path.glob("*progress*"))
    assert str(progress) in capsys.readouterr().out
    exported = tmp_path / "kid-17-export"
    assert main(["data", "export", "--person", "kid-17", "-o", str(exported)]) == 0
    mcap = tmp_path / "b.mcap"
    assert main(["replay", str(recorded[1]), "--to", "mcap", "-o", str(mcap)]) == 0
    (site_data / "site.yaml").write_text("keep_sessions_days: 0.0001\n")  # about 9 s
    monkeypatch.setattr("engine.cli.site_access.EpochClock", lambda: Calendar(4e9))
    capsys.readouterr()
    assert main(["data", "purge"]) == 0
    said = capsys.readouterr().out
    for copy in (progress, exported, mcap):
        assert not copy.exists() and f"removed {copy.resolve()}" in said, copy
    assert "3 sessions older than" in said


def test_what_a_purge_cannot_remove_is_named_and_tried_again(
    recorded: list[Path],
    site_data: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    held = tmp_path / "held"
    held.mkdir()
    exported = held / "kid-17-export"
    assert main(["data", "export", "--person", "kid-17", "-o", str(exported)]) == 0
    stuck = exported / "sessions" / "999-notes.json"  # a folder where vest wrote files
    stuck.mkdir()
    (site_data / "site.yaml").write_text("keep_sessions_days: 0.0001\n")
    monkeypatch.setattr("engine.cli.site_access.EpochClock", lambda: Calendar(4e9))
    capsys.readouterr()
    assert main(["data", "purge"]) == 1
    said = capsys.readouterr().err
    assert f"could not remove {exported.resolve()}" in said and "by hand" in said
    stuck.rmdir()
    assert main(["data", "purge"]) == 0  # still listed: tried again
    assert not exported.exists()


def test_a_site_setting_with_a_mistake_is_named(site_data: Path) -> None:
    site_data.mkdir(parents=True)
    (site_data / "site.yaml").write_text("keep_sesions_days: 30\n")
    with pytest.raises(ConfigError, match=r"site.yaml:1:1: unknown site field 'keep_sesions_days'"):
        Site.open(site_data, clock=Calendar(0), who="ana")


def test_after_a_new_key_the_old_one_reads_nothing(
    recorded: list[Path], site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    old = (site_data / "site.key").read_text()
    assert main(["data", "rekey"]) == 0
    assert "4 files encrypted with a new key" in capsys.readouterr().out
    assert (site_data / "site.key").read_text() != old
    assert main(["replay", str(recorded[0])]) == 0
    (site_data / "site.key").write_text(old)
    with pytest.raises(ConfigError, match="cannot be read with this site's key"):
        Site.open(site_data, clock=Calendar(0), who="ana")


def test_a_rotation_cut_off_is_finished_by_running_it_again(
    recorded: list[Path], site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site = Site.open(site_data, clock=Calendar(1e9), who="ana")
    from engine.privacy.sealed_sqlite import rekey
    from engine.privacy.site import site_key_in_rotation

    new = site_key_in_rotation(site_data)
    rekey(recorded[0], site.key, new)  # one recording done, then the power went
    site.close()
    assert main(["data", "list"]) == 0
    assert "a key rotation was cut off" in capsys.readouterr().err
    assert main(["data", "rekey"]) == 0
    assert "3 files encrypted with a new key" in capsys.readouterr().out
    for path in recorded:
        assert main(["replay", str(path)]) == 0


def test_a_recording_of_an_earlier_vest_is_read_and_can_be_sealed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], the_site_key
) -> None:
    kept = tmp_path / "old.db"
    kept.write_bytes((ROOT / "tests/recordings/unplug_touch.format1.db").read_bytes())
    assert main(["replay", str(kept)]) == 0
    assert "is not encrypted (recorded before vest sealed recordings)" in capsys.readouterr().err
    assert main(["data", "seal", str(kept)]) == 0
    assert not kept.read_bytes().startswith(b"SQLite format 3")
    connect_sealed(kept, the_site_key, read_only=True).close()
    assert main(["replay", str(kept), "--at", "4.5"]) == 0
    assert "/devices/touch/ok = false" in capsys.readouterr().out


def test_the_audit_trail_names_the_operating_system_s_account_not_a_variable(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import os
    import pwd

    monkeypatch.setenv("LOGNAME", "mallory")
    monkeypatch.setenv("USER", "mallory")
    assert main(["data", "consent", "kid-9", "--given-by", "guardian", "--covers", "sensors"]) == 0
    capsys.readouterr()
    assert main(["data", "audit", "--json"]) == 0
    who = json.loads(capsys.readouterr().out.splitlines()[-1])["who"]
    uid = os.geteuid()
    assert who == f"{pwd.getpwuid(uid).pw_name} (uid {uid})" and "mallory" not in who


def test_copies_made_from_a_moved_recording_and_the_robot_s_voice_are_erased_too(
    recorded: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A breaker's find: a recording moved away from where it was recorded still made
    reports the erasure did not know of, and `--audio-out` kept what the robot said (a
    sentence may quote the child) in files named with its words."""
    moved = tmp_path / "usb" / "a-copy.vest"
    moved.parent.mkdir()
    recorded[0].rename(moved)
    assert main(["report", str(moved), "-o", str(tmp_path / "usb" / "copy.html")]) == 0
    voice = tmp_path / "voice"
    args = ["run", "--fast", "--speech", "text", "--duration", "2", "--person", "kid-17"]
    assert main([*args, "--audio-out", str(voice)]) == 0
    voice.mkdir(exist_ok=True)  # with the speech models, --audio-out writes a file a sentence
    (voice / "001-robot.wav").write_bytes(b"RIFF")
    (voice / "notes.txt").write_text("the therapist's own")
    capsys.readouterr()
    assert main(["data", "erase", "--person", "kid-17", "--yes"]) == 0
    assert not (tmp_path / "usb" / "copy.html").exists()
    assert not (voice / "001-robot.wav").exists() and (voice / "notes.txt").exists()
    assert main(["replay", str(moved)]) == 1  # the copy the erasure could not find
    assert "whose data was erased" in capsys.readouterr().err


def test_a_report_says_what_the_person_s_consent_kept_out_of_it(
    recorded: list[Path], tmp_path: Path
) -> None:
    """A new user's find: a report of a session without consent to readings showed no
    squeeze and empty charts, and said nothing of why."""
    assert main(["report", str(recorded[2]), "-o", str(tmp_path / "c.html")]) == 0  # kid-4
    page = (tmp_path / "c.html").read_text()
    assert "not kept of this person" in page and "what the person said is not in" in page
    assert "touches, squeezes" not in page  # readings were kept
    assert main(["report", str(recorded[0]), "-o", str(tmp_path / "a2.html")]) == 0  # kid-17
    assert "what the person said is not in" not in (tmp_path / "a2.html").read_text()


def test_a_consent_given_wrong_is_refused_and_leaves_nothing_behind(
    site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    given = ["data", "consent", "kid-3", "--covers", "sensors"]
    assert main([*given, "--given-by", "Maria"]) == 2
    assert "a role in lower case" in capsys.readouterr().err
    assert (
        main([*given, "--given-by", "guardian", "--on", "2026-11-20", "--until", "2026-01-01"]) == 2
    )
    assert "before the day consent was given (2026-11-20)" in capsys.readouterr().err
    assert not list(site_data.glob("*.partial")) and not (site_data / "consent.yaml").exists()


def test_erasing_one_person_of_a_file_in_flow_style_keeps_everyone_else(
    site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a breaker's file: written by hand on one line
    site_data.mkdir(mode=0o700, parents=True, exist_ok=True)
    (site_data / "consent.yaml").write_text(
        "{kid-1: {given_by: guardian, given_on: 2026-01-05, covers: [sensors]},"
        " kid-2: {given_by: parent, given_on: 2026-02-01, covers: [sensors, speech_text]}}\n"
    )
    assert main(["data", "erase", "--person", "kid-1", "--yes"]) == 0
    capsys.readouterr()
    assert main(["data", "consent", "kid-2"]) == 0
    assert "keeps sensor readings, speech as text" in capsys.readouterr().out  # as it was
    assert "kid-1" not in (site_data / "consent.yaml").read_text()
    assert (site_data / "consent.yaml").stat().st_mode & 0o777 == 0o600


def test_a_record_that_would_leave_the_file_unreadable_names_the_file_not_a_temporary(
    site_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site_data.mkdir(mode=0o700, parents=True, exist_ok=True)
    flow = "{kid-1: {given_by: guardian, given_on: 2026-01-05, covers: [sensors]}}"  # no newline
    (site_data / "consent.yaml").write_text(flow)
    given = ["data", "consent", "kid-2", "--given-by", "guardian", "--covers", "sensors"]
    assert main(given) == 1
    told = capsys.readouterr().err
    assert f"{site_data / 'consent.yaml'}: not changed: with kid-2 added" in told
    assert ".tmp" not in told
    assert (site_data / "consent.yaml").read_text() == flow
    assert sorted(p.name for p in site_data.iterdir() if "consent" in p.name) == [
        "consent.lock",
        "consent.yaml",
    ]


@pytest.mark.realtime
def test_guardians_consenting_at_the_same_moment_are_all_kept(site_data: Path) -> None:
    # four `vest data consent` at once, as two staff members at two terminals might
    vest = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
    adding = [
        subprocess.Popen(
            [*vest, "data", "consent", f"kid-{n}", "--given-by", "guardian", "--covers", "sensors"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        for n in range(1, 5)
    ]
    for process in adding:
        _, err = process.communicate(timeout=120)
        assert process.returncode == 0, err
    text = (site_data / "consent.yaml").read_text()
    assert all(f"kid-{n}:" in text for n in range(1, 5)), text


def test_a_capture_named_twice_is_kept_once(site_data: Path) -> None:
    given = ["data", "consent", "kid-4", "--given-by", "guardian", "--covers", "sensors,sensors"]
    assert main(given) == 0
    assert "covers: [sensors]\n" in (site_data / "consent.yaml").read_text()
