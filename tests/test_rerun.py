"""A recorded session played again against changed trees: a test sees what an edit would
have changed in a real session (the py_trees users' wish, issue #419)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.site_data import site_key
from engine.recording.replay import Recording
from engine.recording.rerun import compare, rerun
from engine.runtime.robot import load_behaviors

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Recording:
    path = tmp_path_factory.mktemp("rerun") / "demo.db"
    site = tmp_path_factory.mktemp("rerun-site")
    (site / "consent.yaml").write_text(  # what was heard is kept: the dialog replays too
        "kid-3:\n  given_by: guardian\n  given_on: 2026-01-05\n  covers: [sensors, speech_text]\n"
    )
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(ROOT)
        patch.setenv("VEST_DATA", str(site))
        args = ["run", "--fast", "--speech", "text", "--record", str(path), "--person", "kid-3"]
        assert main(args) == 0
    return Recording.open(path, site_key(site, create=False))


def trees(folder: Path) -> object:
    return load_behaviors([folder], dialogs_dir=ROOT / "dialogs")


def test_the_same_trees_do_what_they_did(session: Recording) -> None:
    assert compare(session.actions(), rerun(session, trees(ROOT / "trees"))) == []


def test_a_firmer_hug_threshold_would_have_missed_the_child_s_hug(
    session: Recording, tmp_path: Path
) -> None:
    edited = tmp_path / "trees"
    shutil.copytree(ROOT / "trees", edited)
    hug = edited / "hug.yaml"
    hug.write_text(hug.read_text().replace("hug_threshold_n: 3.0", "hug_threshold_n: 8.0"))
    differences = compare(session.actions(), rerun(session, trees(edited)))
    assert [(d.side, d.action.tree, d.action.action) for d in differences] == [
        ("recorded", "hug", "led"),
        ("recorded", "hug", "say"),
    ]
    assert "hug: say {'text': 'I love hugs!', 'volume': 0.8} was taken, not now" in str(
        differences[1]
    )
