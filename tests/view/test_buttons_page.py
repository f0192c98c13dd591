"""The therapist's buttons in a real browser (Debian's chromium driven by Playwright):
`vest run --buttons` serves the page; a click or a key takes over from the behaviors at
once; buttons show only when they make sense; another site cannot press them."""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import threading
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Page, expect

ROOT = Path(__file__).resolve().parents[2]
VEST = "import sys; from engine.cli import main; sys.exit(main())"
BUTTONS = ROOT / "trees" / "buttons" / "session.yaml"
VEST_RUN = [sys.executable, "-c", VEST, "run", "--speech", "text"]


class Session:
    """`vest run --buttons` in real time on a quiet scenario: its address and timeline."""

    def __init__(self, tmp_path: Path) -> None:
        scenario = tmp_path / "quiet.yaml"
        scenario.write_text("duration_s: 120\nevents: []\n")
        self.process = subprocess.Popen(
            [*VEST_RUN, "--scenario", str(scenario), "--buttons", str(BUTTONS), "--view-port", "0"],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        assert self.process.stderr is not None and self.process.stdout is not None
        self.address = ""
        for line in self.process.stderr:
            if line.startswith("buttons: "):
                self.address = line.removeprefix("buttons: ").strip()
                break
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []  # every timeline line read so far
        stdout = self.process.stdout
        threading.Thread(target=lambda: [self.lines.put(x) for x in stdout], daemon=True).start()

    def wait_for(self, text: str, timeout_s: float = 15.0) -> str:
        """The next timeline line containing ``text`` (a failure after ``timeout_s``)."""
        seen = []
        while True:
            try:
                line = self.lines.get(timeout=timeout_s)
            except queue.Empty:
                raise AssertionError(f"no line with {text!r}; saw {seen}") from None
            seen.append(line.rstrip())
            self.seen.append(line.rstrip())
            if text in line:
                return line

    def stop(self) -> None:
        self.process.send_signal(signal.SIGTERM)
        self.process.wait(timeout=30)


@pytest.fixture
def session(tmp_path: Path) -> Iterator[Session]:
    running = Session(tmp_path)
    try:
        assert running.address.startswith("http://127.0.0.1:"), "no buttons address printed"
        yield running
    finally:
        running.stop()


def button(page: Page, label: str):
    return page.get_by_role("button", name=label)


def test_a_click_makes_the_robot_speak_at_once(page: Page, session: Session) -> None:
    page.goto(session.address)
    button(page, "Hello h").click()
    session.wait_for("therapist      presses the button 'Hello'")
    session.wait_for('buttons        says "Hello! I am happy to see you."')


def test_a_key_pauses_the_behaviors_and_only_resume_shows_then(
    page: Page, session: Session
) -> None:
    page.goto(session.address)
    expect(button(page, "Pause p")).to_be_visible()
    expect(button(page, "Resume r")).to_be_hidden()
    page.keyboard.press("p")
    session.wait_for("buttons        pauses the behaviors")
    expect(page.locator("#state")).to_contain_text("behaviors paused")
    expect(button(page, "Resume r")).to_be_visible()
    expect(button(page, "Pause p")).to_be_hidden()
    page.keyboard.press("r")
    session.wait_for("buttons        resumes the behaviors")
    expect(button(page, "Pause p")).to_be_visible()


def test_a_button_for_the_counting_game_shows_only_while_the_game_runs(
    page: Page, session: Session
) -> None:
    page.goto(session.address)
    expect(button(page, "Hello h")).to_be_visible()
    expect(button(page, "Show me your hand s")).to_be_hidden()


def post(address: str, body: bytes, headers: dict[str, str]) -> int:
    url = address.replace("/buttons", "/api/press")
    request = urllib.request.Request(url, data=body, headers=headers, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status
    except urllib.error.HTTPError as error:
        return error.code


def test_another_site_cannot_press_a_button_and_bad_presses_are_refused(
    session: Session,
) -> None:
    press = json.dumps({"button": 0}).encode()
    as_json = {"Content-Type": "application/json"}
    assert post(session.address, press, {**as_json, "Origin": "http://evil.example"}) == 403
    assert post(session.address, press, {"Content-Type": "text/plain"}) == 400
    assert post(session.address, b"{not json", as_json) == 400
    assert post(session.address, json.dumps({"button": 99}).encode(), as_json) == 404
    assert post(session.address, press, as_json) == 202  # the page's own way
    session.wait_for('buttons        says "Hello! I am happy to see you."')


def test_on_the_simulated_vest_the_page_squeezes_and_speaks_for_the_child(
    page: Page, session: Session
) -> None:
    page.goto(session.address)
    vest = page.get_by_role("region", name="Act on the simulated vest")
    expect(vest).to_be_visible()
    vest.get_by_role("button", name="Squeeze").click()
    session.wait_for("world          squeezed left 6 N, right 6 N for 1.5 s")
    expect(page.locator("#acted")).to_contain_text("done: squeezed left 6 N")
    # typing the child's words presses no button, even letters that are buttons' keys
    vest.get_by_label("Say as the child").press_sequentially("what is your name")
    vest.get_by_role("button", name="Say it").click()
    session.wait_for("world          someone says 'what is your name'")
    session.wait_for('dialog         says "My name is H B S 2"')
    assert not [line for line in session.seen if "presses the button" in line]
    # the page tells what the robot said, without its terminal
    expect(page.locator("#happened")).to_contain_text('dialog: says "My name is H B S 2"')
    vest.get_by_label("for").first.fill("0")  # below what the page allows: the robot says
    page.evaluate("document.querySelector('#act-squeeze input[name=seconds]').min = ''")
    vest.get_by_role("button", name="Squeeze").click()
    expect(page.locator("#acted")).to_contain_text("'seconds' must be")


def test_a_bad_act_is_refused_with_its_place(session: Session) -> None:
    url = session.address.replace("/buttons", "/api/act")
    as_json = {"Content-Type": "application/json"}
    request = urllib.request.Request(url, data=b'{"cloud": {}}', headers=as_json, method="POST")
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(request, timeout=10)
    assert refused.value.code == 422
    assert refused.value.read().decode().startswith("the request:1:2: the page cannot act")
