"""A therapist in the next room: she opens the robot on the cloud's page, sees its session
(its trees, what happened, its buttons) and presses a button; the robot carries the press
out as a press on its own buttons page, credited to her. A viewer sees, never presses; a
press the robot cannot take in time is dropped, and said so."""

from __future__ import annotations

import http.server
import signal
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import requests
from playwright.sync_api import Page, expect

from cloud.api.presses import PRESS_WITHIN_S
from cloud.settings import Settings
from cloud.store.ledger import FAILED, SUCCEEDED, TIMED_OUT
from engine.clock import RealClock, VirtualClock
from engine.services.done_commands import DoneCommands
from tests.cloud.conftest import Robot, Running, StartService

REAL = RealClock()
WAITS_MS = 60_000
"""How long the page may take to show what the robot did (only ends a broken test: a
loaded machine is slow, never wrong)."""


def until(what: Callable[[], Any], limit_s: float = 120.0) -> Any:
    """``what()`` once it is truthy; the limit only ends a broken test (real seconds)."""
    deadline_s = REAL.now() + limit_s
    while not (found := what()):
        assert REAL.now() < deadline_s, "never came"
        REAL.sleep(0.05)
    return found


def people(running: Running, tmp_path: Path) -> tuple[dict[str, str], Path]:
    """tess (therapist) and val (viewer) may see hbs2; its token file."""
    directory = running.store.directory
    directory.add_operator("ana")
    token_file = tmp_path / "robot.token"
    token_file.write_text(directory.add_robot("hbs2", operator="ana") + "\n")
    tokens = {}
    for name, role in (("tess", "therapist"), ("val", "viewer")):
        tokens[name] = directory.add_operator(name, role=role)
        directory.grant(name, "hbs2")
    return tokens, token_file


def with_buttons(
    start_robot: Callable[..., Robot], running: Running, token_file: Path, tree: str
) -> Robot:
    """`vest run --buttons --cloud` with ``tree`` on the simulated vest, for ten minutes."""
    scenario = token_file.parent / "long.yaml"
    scenario.write_text("duration_s: 600\nevents: []\n")
    return start_robot(
        running.url, token_file, scenario, [tree], buttons="trees/buttons/session.yaml"
    )


def failed(running: Running, command_id: str) -> Any:
    """The command once it ended FAILED, else None."""
    found = running.store.ledger.get(1, command_id)
    return found if found is not None and found.state == FAILED else None


def as_(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


def test_a_therapist_in_the_next_room_watches_the_session_and_presses_a_button(
    start_service: StartService,
    start_robot: Callable[..., Robot],
    tmp_path: Path,
) -> None:
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", recheck_s=0.2))
    tokens, token_file = people(running, tmp_path)
    robot = with_buttons(start_robot, running, token_file, "trees/touch_thanks.yaml")
    session_url = f"{running.api}/robots/hbs2/session"

    def board() -> dict[str, Any] | None:
        answer = requests.get(session_url, headers=as_(tokens["tess"]), timeout=10)
        return answer.json()["view"] if answer.status_code == 200 else None

    view = until(board)
    assert [tree["tree"] for tree in view["trees"]] == ["buttons", "touch_thanks"]
    labels = [button["label"] for button in view["board"]["buttons"]]
    hello = labels.index("Hello")
    assert hello in view["board"]["shown"] and view["board"]["paused"] is False

    # the viewer sees the buttons and the behaviors, not what happened (it can quote the
    # child), and cannot press
    as_viewer = requests.get(session_url, headers=as_(tokens["val"]), timeout=10).json()["view"]
    assert as_viewer["board"] == view["board"] and as_viewer["trees"]
    assert as_viewer["happened"] == [] and as_viewer["happened_hidden"] is True
    refused = requests.post(
        f"{running.api}/robots/hbs2/press", json={"button": hello}, headers=as_(tokens["val"])
    )
    assert refused.status_code == 403 and "press the robot's buttons" in refused.text

    pressed = requests.post(
        f"{running.api}/robots/hbs2/press", json={"button": hello}, headers=as_(tokens["tess"])
    )
    assert pressed.status_code == 202, pressed.text
    said = robot.until(lambda action: action["action"] == "say")
    assert said["tree"] == "buttons" and said["args"]["text"] == "Hello! I am happy to see you."
    robot_id = running.store.directory.granted_robot  # noqa: F841 (documentation)
    command_id = pressed.json()["id"]
    row = until(
        lambda: next(
            (
                c
                for c in running.store.ledger.recent(1)
                if c.id == command_id and c.state == SUCCEEDED
            ),
            None,
        )
    )
    assert row.result == {"pressed": "Hello"}

    # the page's "what happened" says who pressed, in the live view's words
    told = until(
        lambda: [
            line["what"]
            for line in (board() or {"happened": []})["happened"]
            if "from the cloud" in line["what"]
        ]
    )
    assert told == ["presses the button 'Hello' from the cloud (tess)"]

    # what the robot's own page would refuse, it refuses, saying why; nothing is done
    for number, why in (
        (labels.index("Show me your hand"), "is not shown now"),
        (99, "no button 99"),
    ):
        refused_id = requests.post(
            f"{running.api}/robots/hbs2/press", json={"button": number}, headers=as_(tokens["tess"])
        ).json()["id"]
        ended = until(lambda i=refused_id: failed(running, i))
        assert why in ended.result["error"]

    robot.process.send_signal(signal.SIGINT)
    robot.finish()
    presses = [event for event in robot.events if event["event"] == "press"]
    assert [(p["label"], p["by"], p["who"]) for p in presses] == [("Hello", "cloud", "tess")]
    audit = [(e.actor, e.action, e.detail) for e in running.store.directory.audit.since()]
    assert ("tess", "press", f"button {hello} 'Hello'") in audit


def test_a_press_reaches_a_robot_busy_with_an_operator_s_long_command(
    start_service: StartService, start_robot: Callable[..., Robot], tmp_path: Path
) -> None:
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", recheck_s=0.2))
    tokens, token_file = people(running, tmp_path)
    long_say, _ = running.store.ledger.submit(1, "say", {"text": " ".join(["one two three"] * 20)})
    robot = with_buttons(start_robot, running, token_file, "trees/iot_command.yaml")
    robot.until(lambda action: action["action"] == "say")  # the long sentence has begun
    view = until(
        lambda: (
            requests.get(f"{running.api}/robots/hbs2/session", headers=as_(tokens["tess"]))
            .json()
            .get("view")
        )
    )
    calm = [button["label"] for button in view["board"]["buttons"]].index("Calm face")
    requests.post(
        f"{running.api}/robots/hbs2/press", json={"button": calm}, headers=as_(tokens["tess"])
    )
    lit = robot.until(lambda action: action["action"] == "led" and action["tree"] == "buttons")
    assert lit["args"]["color"] == "blue"
    still = running.store.ledger.get(1, long_say.id)
    assert still is not None and still.state == "IN_PROGRESS"  # the press did not wait for it
    robot.process.send_signal(signal.SIGINT)
    robot.finish()


def test_a_view_or_a_press_of_another_shape_is_refused_by_name(
    start_service: StartService, tmp_path: Path
) -> None:
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"))
    tokens, token_file = people(running, tmp_path)
    robot = {"Authorization": f"Bearer {token_file.read_text().strip()}"}
    for view, field in (
        ({}, "view.trees"),
        ({"trees": [], "happened": [{"at": 1, "who": "x", "what": 3, "tone": ""}]}, "what"),
        (
            {
                "trees": [],
                "happened": [],
                "board": {"buttons": [], "shown": ["1"], "paused": False},
            },
            "shown",
        ),
    ):
        refused = requests.post(f"{running.api}/robot/session", json={"view": view}, headers=robot)
        assert refused.status_code == 422 and field in refused.text, refused.text
    assert running.store.sessions.get(1) is None  # nothing a page would trip over was kept
    for button in (True, "1", -1, 1.5):
        pressed = requests.post(
            f"{running.api}/robots/hbs2/press", json={"button": button}, headers=as_(tokens["tess"])
        )
        assert pressed.status_code == 422, (button, pressed.text)


def test_a_press_the_robot_does_not_take_in_time_is_dropped_never_carried_out_late(
    start_service: StartService, tmp_path: Path
) -> None:
    clock = VirtualClock(start_s=1000.0)
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"), clock)
    tokens, _ = people(running, tmp_path)
    pressed = requests.post(
        f"{running.api}/robots/hbs2/press", json={"button": 0}, headers=as_(tokens["tess"])
    )
    assert pressed.status_code == 202
    clock.advance(PRESS_WITHIN_S + 0.01)  # the robot was away all along
    ledger = running.store.ledger
    assert ledger.claim_next(1) is None  # never handed to it now
    (command,) = ledger.recent(1)
    assert command.id == pressed.json()["id"] and command.state == TIMED_OUT


def test_on_the_cloud_page_a_therapist_presses_and_a_viewer_only_watches(
    start_service: StartService,
    start_robot: Callable[..., Robot],
    tmp_path: Path,
    page: Page,
) -> None:
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", recheck_s=0.2))
    tokens, token_file = people(running, tmp_path)
    robot = with_buttons(start_robot, running, token_file, "trees/touch_thanks.yaml")
    page.goto(running.url)
    page.fill("#token", tokens["tess"])
    page.click("#login button[type=submit]")
    hello = page.locator('#session-board button:text-is("Hello")')
    expect(hello).to_be_enabled(timeout=60_000)
    expect(page.locator('#session-board button:text-is("Show me your hand")')).to_be_disabled()
    expect(page.locator('#session-trees li[data-tree="touch_thanks"]')).to_be_visible()
    hello.click()
    expect(page.locator("#press-outcome")).to_have_text(
        "Hello: done by the robot", timeout=WAITS_MS
    )
    expect(page.locator("#session-happened")).to_contain_text(
        "presses the button 'Hello' from the cloud (tess)", timeout=WAITS_MS
    )
    expect(page.locator("#session-happened")).to_contain_text('says "Hello! I am happy')

    page.click("#logout")  # the page loads again: log in on the new one, not the old
    expect(page.locator("#login")).to_be_visible(timeout=WAITS_MS)
    page.fill("#token", tokens["val"])
    page.click("#login button[type=submit]")
    expect(page.locator("#no-happened")).to_have_text(
        "What happened is not shown to your role, viewer: it can quote the child.",
        timeout=WAITS_MS,  # logging in again and the stream's first event
    )
    expect(page.locator('#session-board button:text-is("Hello")')).to_be_disabled()
    expect(page.locator("#board-role")).to_have_text(
        "Your role, viewer, sees the buttons; it does not press them."
    )

    robot.process.send_signal(signal.SIGINT)  # the robot stops: the page says so at once
    robot.finish()
    expect(page.locator("#session-stale")).to_contain_text(
        "The session has ended", timeout=WAITS_MS
    )


class HoldingProxy:
    """The robot's network to the service, on loopback: it passes every request on, and
    holds a claimed command's reply while ``holding`` is clear (a slow wifi link)."""

    def __init__(self, service: str) -> None:
        self.holding = threading.Event()
        self.holding.set()
        self.held = threading.Event()
        proxy = self
        upstream = requests.Session()
        upstream.trust_env = False

        class Handler(http.server.BaseHTTPRequestHandler):
            def _pass_on(self) -> None:
                length = int(self.headers.get("content-length") or 0)
                answer = upstream.request(
                    self.command,
                    service + self.path,
                    data=self.rfile.read(length) if length else None,
                    headers={k: v for k, v in self.headers.items() if k.lower() != "host"},
                    timeout=60,
                )
                if answer.status_code == 200 and "/commands/next" in self.path:
                    proxy.held.set()
                    proxy.holding.wait(60)
                self.send_response(answer.status_code)
                for name in ("content-type",):
                    if name in answer.headers:
                        self.send_header(name, answer.headers[name])
                self.send_header("content-length", str(len(answer.content)))
                self.end_headers()
                self.wfile.write(answer.content)

            def do_GET(self) -> None:
                self._pass_on()

            def do_POST(self) -> None:
                self._pass_on()

            def log_message(self, *args: Any) -> None:
                pass

        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.holding.set()
        self.server.shutdown()


def test_a_press_that_reaches_the_robot_too_late_is_dropped_not_carried_out(
    start_service: StartService, start_robot: Callable[..., Robot], tmp_path: Path
) -> None:
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", recheck_s=0.2))
    tokens, token_file = people(running, tmp_path)
    network = HoldingProxy(running.url)
    try:
        slow = Running(network.url, running.store)  # the robot reaches the service through it
        robot = with_buttons(start_robot, slow, token_file, "trees/touch_thanks.yaml")
        view = until(lambda: running.store.sessions.get(1))[0]
        hello = [button["label"] for button in view["board"]["buttons"]].index("Hello")
        network.holding.clear()
        press = requests.post(
            f"{running.api}/robots/hbs2/press", json={"button": hello}, headers=as_(tokens["tess"])
        ).json()
        assert network.held.wait(60)  # the robot claimed it; its reply is on the slow link
        until(lambda: running.store.ledger.get(1, press["id"]).state == TIMED_OUT)  # type: ignore[union-attr]
        network.holding.set()  # the press reaches the robot, past its 2 s
        done = DoneCommands(token_file.parent / "robot.token.done.json")
        dropped = until(lambda: DoneCommands(done.path).get(press["id"]))  # its record says
        robot.process.send_signal(signal.SIGINT)
        robot.finish()
    finally:
        network.close()
    assert dropped["status"] == "FAILED" and "never carried out late" in dropped["result"]["error"]
    assert not [e for e in robot.events if e["event"] == "press"]  # never carried out
    assert running.store.ledger.get(1, press["id"]).state == TIMED_OUT  # type: ignore[union-attr]
