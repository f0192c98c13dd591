"""A session recorded with `vest run --record` and looked at again with `vest replay`."""

from __future__ import annotations

import os
import shutil
import sqlite3
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.sealed_sqlite import connect_sealed
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording
from engine.recording.session_file import COLUMNS, FORMAT_VERSION

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def demo(tmp_path: Path, capsys, monkeypatch) -> Path:
    """The demo scenario, run on the virtual clock and recorded."""
    monkeypatch.chdir(ROOT)
    path = tmp_path / "demo.db"
    assert main(["run", "--fast", "--speech", "text", "--record", str(path)]) == 0
    capsys.readouterr()
    return path


def test_the_recording_holds_every_tree_as_vest_render_draws_it(
    demo: Path, the_site_key: SiteKey
) -> None:
    recording = Recording.open(demo, the_site_key)
    names = [tree.name for tree in recording.trees]
    assert {"hug", "dialog", "touch_thanks", "finger_game"} <= set(names)
    hug = next(tree for tree in recording.trees if tree.name == "hug")
    assert hug.rate_hz == 20.0 and len(hug.digest) == 64
    assert hug.nodes[0].index == 0 and hug.nodes[0].depth == 0
    source, dot = (
        connect_sealed(demo, the_site_key)
        .execute("SELECT source, dot FROM trees WHERE tree = 'hug'")
        .fetchone()
    )
    assert "name: hug" in source
    assert all(f"n{node.index} [" in dot for node in hug.nodes)
    assert recording.duration_s == pytest.approx(32.0, abs=0.2)


def test_at_a_moment_the_hug_is_running_and_the_squeeze_is_on_the_blackboard(
    demo: Path, the_site_key: SiteKey
) -> None:
    recording = Recording.open(demo, the_site_key)
    hug = next(tree for tree in recording.trees_at(3.5) if tree.name == "hug")
    statuses = recording.statuses_at(3.5)
    root = statuses[("hug", hug.version, 0)]
    assert root.status == "RUNNING" and 3.0 <= root.since_s < 3.5
    board = recording.blackboard_at(3.5)
    assert board["/sensors/force/left_n"].value > 5.0
    assert recording.blackboard_at(0.5)["/sensors/force/left_n"].value == 0.0
    said = [a.args["text"] for a in recording.actions(4.0) if a.action == "say"]
    assert said == ["Thank you", "I love hugs!"]


def test_vest_replay_at_prints_the_trees_and_the_blackboard(demo: Path, capsys) -> None:
    assert main(["replay", str(demo), "--at", "3.5"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("at 3.50 s of 32.")
    assert "\nhug (20 Hz)\n  [..] " in out
    assert "/sensors/force/left_n = " in out
    assert "[ok] success  [no] failure  [..] running  [  ] not ticked" in out


def test_vest_replay_without_a_moment_says_what_the_recording_holds(demo: Path, capsys) -> None:
    assert main(["replay", str(demo)]) == 0
    out = capsys.readouterr().out
    assert "a session of 32." in out and "hug: 7 nodes at 20 Hz" in out


def test_a_moment_after_the_session_is_refused_in_words(demo: Path, capsys) -> None:
    assert main(["replay", str(demo), "--at", "99"]) == 2
    assert "--at 99: the session lasted 32." in capsys.readouterr().err


def test_a_file_that_is_not_a_recording_is_named(tmp_path: Path, capsys) -> None:
    text = tmp_path / "notes.db"
    text.write_text("hello")
    assert main(["replay", str(text)]) == 1
    assert "notes.db: not a vest recording" in capsys.readouterr().err
    assert main(["replay", str(tmp_path / "gone.db")]) == 1
    assert "gone.db: no such recording" in capsys.readouterr().err


def test_a_recording_from_a_newer_vest_is_refused_by_its_format(
    demo: Path, capsys, the_site_key: SiteKey
) -> None:
    with connect_sealed(demo, the_site_key) as db:
        db.execute("UPDATE meta SET value = '99' WHERE key = 'format'")
    assert main(["replay", str(demo)]) == 1
    assert (
        f"recorded in format 99, newer than this vest reads ({FORMAT_VERSION})"
        in capsys.readouterr().err
    )


def test_recording_into_a_missing_folder_stops_before_the_robot_starts(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    monkeypatch.chdir(ROOT)
    where = tmp_path / "no" / "such" / "s.db"
    assert main(["run", "--fast", "--speech", "text", "--record", str(where)]) == 1
    err = capsys.readouterr().err
    assert "--record" in err and "cannot write a recording there" in err


def test_a_recording_of_format_1_kept_in_the_repository_still_replays(capsys) -> None:
    """Made by vest run --record when format 1 was new: later versions must read it."""
    kept = Path(__file__).parent / "recordings" / "unplug_touch.format1.db"
    assert main(["replay", str(kept), "--at", "4.5"]) == 0
    out = capsys.readouterr().out
    assert "\nhug (20 Hz)\n  [..] " in out  # hugged at 4 s
    assert "/devices/touch/ok = false" in out  # unplugged from 2 s to 6 s


def test_recording_over_a_file_that_is_not_a_recording_is_refused(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    monkeypatch.chdir(ROOT)
    precious = tmp_path / "hug.yaml"
    precious.write_text("name: hug\n")
    assert main(["run", "--fast", "--speech", "text", "--record", str(precious)]) == 1
    assert "holds something else, which a new recording would replace" in (capsys.readouterr().err)
    assert precious.read_text() == "name: hug\n"
    fifo = tmp_path / "fifo.db"
    os.mkfifo(fifo)  # nobody writes it: reading it to see what it holds would wait for ever
    assert main(["run", "--fast", "--speech", "text", "--record", str(fifo)]) == 1
    assert "fifo.db: holds something else" in capsys.readouterr().err


def test_recording_again_under_the_name_of_an_earlier_session_keeps_that_session(
    demo: Path, capsys
) -> None:
    before = demo.read_bytes()
    assert main(["run", "--fast", "--speech", "text", "--record", str(demo)]) == 1
    err = capsys.readouterr().err
    assert "holds an earlier session, which a new recording would replace" in err
    assert demo.read_bytes() == before


def test_at_the_moment_of_an_action_the_tree_that_took_it_shows_running(
    demo: Path, the_site_key: SiteKey
) -> None:
    recording = Recording.open(demo, the_site_key)
    squeeze = next(a for a in recording.actions() if a.tree == "hug")
    hug = next(tree for tree in recording.trees_at(squeeze.at_s) if tree.name == "hug")
    assert recording.statuses_at(squeeze.at_s)[("hug", hug.version, 0)].status == "RUNNING"


def test_a_damaged_recording_is_named_not_a_traceback(
    demo: Path, tmp_path: Path, capsys, the_site_key: SiteKey
) -> None:
    no_nodes = tmp_path / "no_nodes.db"
    no_nodes.write_bytes(demo.read_bytes())
    with connect_sealed(no_nodes, the_site_key) as db:
        db.execute("DROP TABLE nodes")
    bad_length = tmp_path / "bad_length.db"
    bad_length.write_bytes(demo.read_bytes())
    with connect_sealed(bad_length, the_site_key) as db:
        db.execute("UPDATE meta SET value = 'nan' WHERE key = 'duration_s'")
    for broken, why in [(no_nodes, "no table 'nodes'"), (bad_length, "duration nan")]:
        for command in (["replay", str(broken)], ["report", str(broken)]):
            assert main(command) == 1
            err = capsys.readouterr().err
            assert f"{broken.name}: a damaged recording ({why})" in err, err


def test_a_recording_cut_off_mid_write_is_recovered_on_opening(
    demo: Path, tmp_path: Path, the_site_key: SiteKey
) -> None:
    """A robot that lost power while writing leaves SQLite's journal beside the file."""
    cut = tmp_path / "cut.db"
    cut.write_bytes(demo.read_bytes())
    writer = connect_sealed(cut, the_site_key)
    writer.execute("PRAGMA journal_mode=DELETE")
    writer.execute("BEGIN")
    writer.execute("DELETE FROM actions")  # half a batch, never committed
    journal = cut.with_name("cut.db-journal")
    writer.execute("PRAGMA cache_size=1")  # spill to disk: the journal is hot
    assert journal.exists()
    kept = journal.read_bytes()
    writer.close()  # (closing rolls back; put the hot journal back as a power cut leaves it)
    journal.write_bytes(kept)
    recording = Recording.open(cut, the_site_key)
    assert len(recording.actions()) > 10


def test_an_event_s_message_is_not_kept_once_the_node_waits_again(
    demo: Path, the_site_key: SiteKey
) -> None:
    recording = Recording.open(demo, the_site_key)
    wave = next(tree for tree in recording.trees if tree.name == "wave_greeting")
    on_event = next(node for node in wave.nodes if node.type == "OnEvent")
    changes = recording.node_changes("wave_greeting", wave.version, on_event.index)
    took = [i for i, (_, status, _) in enumerate(changes) if status == "SUCCESS"]
    assert took and "swipe_right" in changes[took[0]][2]
    assert changes[took[0] + 1][1:] == ("FAILURE", "")  # waiting again, with nothing to say


@pytest.mark.parametrize(
    "damage",
    [
        "UPDATE actions SET args = '[1,' WHERE rowid = 1",
        "UPDATE actions SET args = '\"text\"' WHERE rowid = 1",
        "UPDATE blackboard SET value = '{' WHERE rowid = 1",
        "UPDATE world SET seq = 'x' WHERE rowid = 1",
        "INSERT INTO events VALUES (1.0, 'safety', '', 'null', 1)",
        "INSERT INTO events VALUES (1.0, 'safety', '', '{\"devices\": 5}', 1)",
        "UPDATE meta SET value = '²' WHERE key = 'dropped'",
        f"UPDATE meta SET value = '{'9' * 5000}' WHERE key = 'dropped'",
        "UPDATE meta SET value = '²' WHERE key = 'format'",
        f"UPDATE meta SET value = '{'9' * 5000}' WHERE key = 'format'",
        "DELETE FROM meta WHERE key = 'duration_s'; UPDATE statuses SET at_s = 1e999",
        "DELETE FROM meta WHERE key = 'duration_s'; UPDATE statuses SET at_s = -50; "
        "UPDATE actions SET at_s = -50; UPDATE blackboard SET at_s = -50",
    ],
)
def test_a_damaged_recording_is_named_in_one_line_by_replay_and_report(
    demo: Path, capsys, damage: str, the_site_key: SiteKey
) -> None:
    with connect_sealed(demo, the_site_key) as connection:
        connection.executescript(damage)
    for command in (["replay", str(demo), "--at", "5"], ["report", str(demo)]):
        code = main(command)
        err = capsys.readouterr().err
        assert "Traceback" not in err
        named = "a damaged recording" in err or "not a vest recording" in err
        assert code == 0 or (code == 1 and named), (command, err)


def test_a_damaged_event_is_named_once_by_the_export_too(
    demo: Path, capsys, the_site_key: SiteKey, tmp_path: Path
) -> None:
    with connect_sealed(demo, the_site_key) as connection:
        connection.execute("UPDATE events SET data = '[1]' WHERE rowid = 1")
        connection.commit()
    out = tmp_path / "demo.mcap"
    assert main(["replay", str(demo), "--to", "mcap", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("a damaged recording") == 1 and "(an event at 0.0 s)" in err, err
    assert not out.exists()  # no half-written file


def test_a_recording_cut_short_says_where_in_replay_and_report_and_exits_1(
    demo: Path, capsys, the_site_key: SiteKey
) -> None:
    with connect_sealed(
        demo, the_site_key
    ) as connection:  # as a full disk leaves it: never finished
        connection.execute("DELETE FROM meta WHERE key = 'duration_s'")
        connection.execute("DELETE FROM actions WHERE at_s > 10")
        connection.execute("DELETE FROM statuses WHERE at_s > 10")
        connection.execute("DELETE FROM blackboard WHERE at_s > 10")
    assert main(["replay", str(demo)]) == 1
    err = capsys.readouterr().err
    assert "the recording was cut short at 10.00 s" in err
    assert main(["report", str(demo)]) == 1
    assert "cut short at 10.00 s" in capsys.readouterr().err
    assert "cut short at 10.00 s" in demo.with_suffix(".html").read_text()


def test_a_recording_whose_meta_is_a_view_that_never_ends_is_refused(
    tmp_path: Path, capsys
) -> None:
    hostile = tmp_path / "hostile.db"
    with sqlite3.connect(hostile) as connection:
        connection.executescript(
            "CREATE VIEW meta AS WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 "
            "FROM n) SELECT 'format' AS key, '1' AS value FROM n;"
        )
    for command in (["replay", str(hostile)], ["report", str(hostile)]):
        assert main(command) == 1
        assert "'meta' is not a table" in capsys.readouterr().err


def test_a_value_of_another_kind_in_any_column_is_a_damaged_recording_never_a_traceback(
    demo: Path, tmp_path: Path, capsys, the_site_key: SiteKey
) -> None:
    """Every column a reader uses, given text where a number is, a number where a word
    is, bytes anywhere: replay and report name the recording as damaged."""
    for table, columns in COLUMNS.items():
        for column in columns:
            for value in ("'x'", "X'00ff'", "1.5"):
                copy = tmp_path / f"{table}.{column}.db"
                shutil.copy(demo, copy)
                with connect_sealed(copy, the_site_key) as connection:  # one row: keys stay unique
                    connection.execute(
                        f"UPDATE {table} SET {column} = {value} "
                        f"WHERE rowid = (SELECT max(rowid) FROM {table})"
                    )
                for command in (["replay", str(copy), "--at", "3"], ["report", str(copy)]):
                    code = main(command)
                    err = capsys.readouterr().err
                    assert code in (0, 1) and "Traceback" not in err, (table, column, value)
                copy.unlink()
