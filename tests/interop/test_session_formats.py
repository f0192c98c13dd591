"""A recorded session opens in the tools labs already use: as MCAP (Foxglove, Lichtblick),
read back here with the ``mcap`` library, and as BehaviorTree.CPP's FileLogger2 log
(Groot2), parsed back here by that format's layout."""

from __future__ import annotations

import json
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from mcap.reader import make_reader

from engine.cli import main
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def demo(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys, consenting) -> Path:
    """The demo, recorded for kid-17 (whose guardian consented to keeping words)."""
    consenting("kid-17", "sensors", "speech_text")
    monkeypatch.chdir(ROOT)
    path = tmp_path / "demo.vest"
    args = ["run", "--fast", "--speech", "text", "--record", str(path), "--person", "kid-17"]
    assert main(args) == 0
    capsys.readouterr()
    return path


def test_the_session_as_mcap_has_a_topic_per_tree_and_one_each_for_the_rest(
    demo: Path, tmp_path: Path, the_site_key: SiteKey, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "demo.mcap"
    assert main(["replay", str(demo), "--to", "mcap", "-o", str(out)]) == 0
    recording = Recording.open(demo, the_site_key)
    with open(out, "rb") as file:
        reader = make_reader(file)
        schemas = {s.name: json.loads(s.data) for s in reader.get_summary().schemas.values()}
        messages = [
            (channel.topic, schema.encoding, message.log_time, json.loads(message.data))
            for schema, channel, message in reader.iter_messages()
        ]
    assert set(schemas) >= {"vest.NodeStatus", "vest.KeyChange", "vest.Action"}
    topics = {topic for topic, *_ in messages}
    trees = {tree.name for tree in recording.trees}
    assert topics >= {f"/vest/trees/{tree}/status" for tree in trees} | {
        "/vest/blackboard",
        "/vest/actions",
        "/vest/actions/outcome",
        "/vest/world",
    }
    assert all(encoding == "jsonschema" for _, encoding, _, _ in messages)
    times = [time for _, _, time, _ in messages]
    assert times == sorted(times)
    said = [
        m["args"]["text"]
        for t, _, _, m in messages
        if t == "/vest/actions" and m["action"] == "say"
    ]
    assert said == [a.args["text"] for a in recording.actions() if a.action == "say"]
    statuses = [m for t, _, _, m in messages if t.endswith("/status")]
    assert len(statuses) == len(recording.table("statuses"))
    started_ns = float(recording.meta["started"]) * 1e9
    assert abs(times[0] - started_ns) < 40e9  # the session's own times, since the epoch
    recording.close()
    assert out.stat().st_mode & 0o077 == 0  # a copy in the clear: its owner's alone
    assert main(["data", "audit", "--person", "kid-17"]) == 0  # and the site knows of it
    assert f"mcap written kid-17: {out}" in capsys.readouterr().out


def read_btlog(path: Path) -> tuple[ET.Element, int, list[tuple[int, int, int]]]:
    """A FileLogger2 file by BehaviorTree.CPP's layout: magic, protocol, xml, first time,
    then 9-byte transitions (6 bytes of microseconds, uid, status)."""
    data = path.read_bytes()
    assert data[:18] == b"BTCPP4-FileLogger2" and data[18] == 1
    (size,) = struct.unpack_from("<i", data, 19)
    xml = ET.fromstring(data[23 : 23 + size].decode("utf-8"))
    (first_us,) = struct.unpack_from("<q", data, 23 + size)
    rest = data[23 + size + 8 :]
    assert len(rest) % 9 == 0
    records = [
        (int.from_bytes(rest[i : i + 6], "little"), *struct.unpack_from("<HB", rest, i + 6))
        for i in range(0, len(rest), 9)
    ]
    return xml, first_us, records


def test_one_tree_of_the_session_as_a_groot2_log(
    demo: Path, tmp_path: Path, capsys, the_site_key: SiteKey
) -> None:
    out = tmp_path / "hug.btlog"
    assert main(["replay", str(demo), "--to", "btlog", "-o", str(out)]) == 2
    assert "--to btlog holds one tree: add --tree, one of" in capsys.readouterr().err
    assert main(["replay", str(demo), "--to", "btlog", "--tree", "hug", "-o", str(out)]) == 0
    xml, first_us, records = read_btlog(out)
    uids = {int(e.attrib["_uid"]): e for e in xml.iter() if "_uid" in e.attrib}
    assert sorted(uids) == list(range(1, len(uids) + 1))  # depth-first from 1
    assert uids[1].tag == "Sequence" and xml.find("TreeNodesModel/Action[@ID='Say']") is not None
    game = tmp_path / "game.btlog"
    args = ["replay", str(demo), "--to", "btlog", "--tree", "finger_game", "-o", str(game)]
    assert main(args) == 0
    tags = {e.tag for e in read_btlog(game)[0].iter()}
    assert "Fallback" in tags and "ReactiveFallback" not in tags  # as vest export writes it
    recording = Recording.open(demo, the_site_key)
    hug = [row for row in recording.table("statuses") if row["tree"] == "hug"]
    assert len(records) == len(hug) > 0
    assert {uid for _, uid, _ in records} <= set(uids)
    assert {status for _, _, status in records} <= {0, 1, 2, 3}
    since = [us for us, _, _ in records]
    assert since == sorted(since) and first_us == round(float(recording.meta["started"]) * 1e6)
    recording.close()


def test_a_conversion_never_writes_over_a_file(demo: Path, capsys) -> None:
    assert main(["replay", str(demo), "--to", "mcap", "-o", str(demo)]) == 2
    assert "a mcap file ends in .mcap" in capsys.readouterr().err
    taken = demo.with_suffix(".mcap")
    taken.write_text("someone's")
    assert main(["replay", str(demo), "--to", "mcap"]) == 1
    assert "is there already" in capsys.readouterr().err and taken.read_text() == "someone's"
