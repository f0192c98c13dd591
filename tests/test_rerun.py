"""A recorded session played again against changed trees: a test sees what an edit would
have changed in a real session (the py_trees users' wish, issue #419)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.sealed_sqlite import connect_sealed
from engine.privacy.site_data import SiteKey, site_key
from engine.recording.replay import Recording
from engine.recording.rerun import _sensed, compare, rerun
from engine.runtime.robot import load_behaviors

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, SiteKey]:
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
    return path, site_key(site, create=False)


@pytest.fixture(scope="module")
def session(recorded: tuple[Path, SiteKey]) -> Recording:
    return Recording.open(*recorded)


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


def test_a_reading_recorded_as_null_is_replayed_as_the_nan_the_trees_saw(
    recorded: tuple[Path, SiteKey], tmp_path: Path
) -> None:
    # a force pad that failed read NaN, kept as null (JSON has none): the trees get NaN
    # again (their worst case), never None, which no comparison takes
    path, key = recorded
    failed = tmp_path / "failed.db"
    shutil.copy(path, failed)
    with connect_sealed(failed, key) as db:
        db.execute("UPDATE blackboard SET value = 'null' WHERE key = '/sensors/force/left_n'")
    recording = Recording.open(failed, key)
    catalogue = trees(ROOT / "trees").loader.catalogue  # type: ignore[attr-defined]
    left = [value for _, k, value, _ in _sensed(recording, catalogue) if k.endswith("left_n")]
    assert left and all(isinstance(v, float) and math.isnan(v) for v in left)
