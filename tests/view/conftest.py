"""What the view's page tests share: the demo served as a replay."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from engine.cli import main
from engine.privacy.site_data import SiteKey
from engine.recording.replay import Recording
from engine.view.replay_source import ReplaySource
from engine.view.server import ViewServer

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def replay(tmp_path: Path, monkeypatch, capsys, the_site_key: SiteKey) -> Iterator[str]:
    """The demo recorded on the virtual clock, served as a replay."""
    monkeypatch.chdir(ROOT)
    recorded = tmp_path / "demo.db"
    assert main(["run", "--fast", "--speech", "text", "--record", str(recorded)]) == 0
    capsys.readouterr()
    recording = Recording.open(recorded, the_site_key)
    server = ViewServer(ReplaySource(recording), port=0)
    server.start()
    yield server.url
    server.stop()
    recording.close()
