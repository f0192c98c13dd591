"""The guides' pictures show what vest shows now: the pages are taken again (Debian's
chromium driven by Playwright) and what each says is compared with what its picture said
when scripts/screenshots.py took it."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

from playwright.sync_api import Page

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "screenshots.py"


def test_every_picture_in_the_guides_shows_what_vest_shows_now(
    page: Page, tmp_path: Path, monkeypatch, site_data: Path
) -> None:
    monkeypatch.chdir(ROOT)
    spec = importlib.util.spec_from_file_location("screenshots", SCRIPT)
    assert spec is not None and spec.loader is not None
    screenshots = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(screenshots)
    page.set_viewport_size(screenshots.VIEWPORT)
    recorded = json.loads((ROOT / "docs" / "images" / "screenshots.json").read_text())
    now = screenshots.shots(page, tmp_path, write=False)
    stale = sorted(name for name in now if recorded.get(name) != now[name])
    assert stale == [], (
        f"docs/images: {', '.join(stale)} no longer show what vest shows; take them again "
        "with .venv/bin/python scripts/screenshots.py and look at them"
    )
    for name in now:
        assert (ROOT / "docs" / "images" / f"{name}.png").is_file()
