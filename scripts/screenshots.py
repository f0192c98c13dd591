"""The guides' pictures (docs/images/*.png), made from the product itself.

Each picture is taken from what vest serves or draws now: the hug tree as `vest render`
draws it, the live view replaying the demo at 7.5 s, the editor with the hug open, and
the demo's session report. Beside the pictures, docs/images/screenshots.json keeps a
digest of what each one shows in words; tests/test_screenshots_current.py takes the same
pages again and fails, naming this script, when a page now says something else than its
picture does.

Run from the project folder: .venv/bin/python scripts/screenshots.py
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import re
import shutil
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
RECORD = IMAGES / "screenshots.json"
VIEWPORT = {"width": 1400, "height": 900}
VOLATILE = (re.compile(r"\d{1,2} \w+ \d{4}, \d\d:\d\d UTC"),)
"""What a page says that differs from one run to the next (a report's date)."""


def words(text: str) -> str:
    """What a page says, as compared: spaces folded, the volatile parts out."""
    for pattern in VOLATILE:
        text = pattern.sub("", text)
    return " ".join(text.split())


def digest(text: str) -> str:
    return hashlib.sha256(words(text).encode()).hexdigest()[:16]


@contextmanager
def demo_recording(folder: Path) -> Iterator[tuple[Path, Any]]:
    """The demo run on the virtual clock and recorded (in a site of its own): its file
    and the site's key."""
    import os

    from engine.cli import main
    from engine.privacy.site_data import site_key

    before = os.environ.get("VEST_DATA")
    os.environ["VEST_DATA"] = str(folder / "site")  # a site of its own, given back after
    recorded = folder / "demo.vest"
    with contextlib.redirect_stdout(io.StringIO()):  # the demo's timeline: not needed here
        code = main(["run", "--fast", "--speech", "text", "--record", str(recorded)])
    if code != 0:
        raise SystemExit(f"the demo did not run ({code})")
    try:
        yield recorded, site_key(folder / "site", create=False)
    finally:
        if before is None:
            del os.environ["VEST_DATA"]
        else:
            os.environ["VEST_DATA"] = before


def shots(page: Any, folder: Path, *, write: bool) -> dict[str, str]:
    """Each picture's digest of what it shows; ``write``: the pictures are taken too."""
    from playwright.sync_api import expect

    from engine.cli import main as vest
    from engine.cli.edit_checks import ValidateChecks
    from engine.cli.run_inputs import DEFAULT_HARDWARE, load_config, load_tree, robot_catalogue
    from engine.editor.palette import palette
    from engine.editor.server import EditorServer
    from engine.editor.workspace import Workspace
    from engine.files.problems import Problems
    from engine.loader.tree_drawing import dot_source
    from engine.nodes.registry import default_registry
    from engine.recording.replay import Recording
    from engine.recording.report import report_html
    from engine.view.replay_source import ReplaySource
    from engine.view.server import ViewServer

    found: dict[str, str] = {}
    hug = ROOT / "trees" / "hug.yaml"
    found["hug-tree"] = digest(dot_source(load_tree(hug, None)[0]))
    if write and vest(["render", str(hug), "--format", "png", "-o", str(IMAGES / "hug-tree.png")]):
        raise SystemExit("vest render could not draw the hug")

    with demo_recording(folder) as (recorded, key):
        recording = Recording.open(recorded, key)
        view = ViewServer(ReplaySource(recording), port=0)
        view.start()
        try:
            page.goto(view.url)
            page.wait_for_selector("body[data-ready=true]")
            page.locator("#slider").evaluate(
                "(s) => { s.value = '7.5'; s.dispatchEvent(new Event('input')); }"
            )
            expect(page.locator("#clock")).to_contain_text("7.5")
            found["live-view"] = digest(page.inner_text("main"))
            if write:
                page.screenshot(path=IMAGES / "live-view.png")
        finally:
            view.stop()
        report = folder / "report.html"
        report.write_text(report_html(recording), encoding="utf-8")
        recording.close()
        page.goto(report.as_uri())
        found["report"] = digest(page.inner_text("body"))
        if write:
            page.screenshot(path=IMAGES / "report.png")

    project = folder / "project"
    for part in ("trees", "dialogs"):
        shutil.copytree(ROOT / part, project / part)
    registry = default_registry()
    config = load_config(ROOT / DEFAULT_HARDWARE, Problems())
    workspace = Workspace(project, registry, ValidateChecks(project, registry, config))
    editor = EditorServer(
        workspace, palette(registry, config, robot_catalogue(config, registry)), port=0
    )
    editor.start()
    try:
        page.goto(editor.url)
        page.wait_for_selector("body[data-ready=true]")
        page.get_by_role("button", name="trees/hug.yaml").click()
        expect(page.locator("#problems")).to_contain_text("vest validate accepts this tree")
        expect(page.locator("#setting-priority-help")).to_contain_text("Other trees")
        page.locator('#outline button[data-path="root/0"]').click()
        found["editor"] = digest(page.inner_text("#editing"))
        page.evaluate("() => window.scrollTo(0, 0)")  # the top of the page, as it opens
        if write:
            page.screenshot(path=IMAGES / "editor.png")
    finally:
        editor.stop()
    return found


@contextmanager
def chromium_page() -> Iterator[Any]:
    """A page of Debian's chromium, driven by Playwright, the size of a laptop's window."""
    from playwright.sync_api import sync_playwright

    chromium = shutil.which("chromium")
    if chromium is None:
        raise SystemExit("Debian's chromium is missing: run scripts/setup")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        try:
            yield browser.new_context(viewport=VIEWPORT).new_page()
        finally:
            browser.close()


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="vest-shots-") as scratch, chromium_page() as page:
        found = shots(page, Path(scratch), write=True)
    RECORD.write_text(json.dumps(found, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    print(f"pictures and what they show: {IMAGES.relative_to(ROOT)}/ ({', '.join(found)})")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
