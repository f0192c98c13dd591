"""The operator's page in a real browser (Debian's chromium driven by Playwright): an
operator logs in, watches a robot on the simulated vest, sends it commands and sees each one
end; on a tablet as on a laptop."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser, Page, expect

from cloud.settings import Settings


@pytest.fixture
def lab(
    tmp_path: Path,
    start_service: Callable[..., Any],
    start_robot: Callable[..., Any],
    consenting: Callable[..., None],
) -> dict[str, Any]:
    """A service with operator ana, robot hbs2 running on the simulated vest in a session
    of kid-9 (whose guardian consented to telemetry), and hbs3 switched off."""
    consenting("kid-9", "sensors", "cloud_telemetry")
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}", recheck_s=0.2))
    directory = running.store.directory
    token = directory.add_operator("ana")
    token_file = tmp_path / "hbs2.token"
    token_file.write_text(directory.add_robot("hbs2", operator="ana"))
    directory.add_robot("hbs3", operator="ana")
    directory.add_operator("zed")
    scenario = tmp_path / "room.yaml"
    scenario.write_text(
        "duration_s: 120\nevents:\n"
        "  - {at: 0.5, obstacle: {left_mm: 250, center_mm: 600, right_mm: 900, seconds: 100}}\n"
    )
    start_robot(running.url, token_file, scenario, ["trees/iot_command.yaml"], person="kid-9")
    return {"url": running.url, "token": token}


def log_in(page: Page, url: str, token: str) -> None:
    page.goto(url)
    page.fill("#token", token)
    page.click("#login button[type=submit]")


def test_a_wrong_token_is_refused_with_a_message(page: Page, lab: dict[str, Any]) -> None:
    log_in(page, lab["url"], "not-a-token")
    expect(page.locator("#login-error")).to_have_text(
        "That token is not valid (or it was revoked)."
    )
    expect(page.locator("#console")).to_be_hidden()


def test_the_token_never_goes_into_the_page_s_address(page: Page, lab: dict[str, Any]) -> None:
    # before the page's script has come (a slow link), the form cannot be sent: sent as
    # a plain form, the token would be in the address, the history and the server's logs
    page.route("**/app.js", lambda route: route.abort())
    page.goto(lab["url"])
    page.fill("#token", lab["token"])
    expect(page.locator("#login button[type=submit]")).to_be_disabled()
    assert page.locator("#token").get_attribute("name") is None
    page.unroute("**/app.js")
    log_in(page, lab["url"], lab["token"])
    expect(page.locator("#console")).to_be_visible()
    assert lab["token"] not in page.url


def test_an_operator_sends_a_say_from_the_page_and_sees_it_succeed(
    page: Page, lab: dict[str, Any]
) -> None:
    log_in(page, lab["url"], lab["token"])
    expect(page.locator("#robots button")).to_have_count(2)
    hbs2 = page.locator('#robots button[data-robot="hbs2"]')
    expect(hbs2).to_contain_text("online", timeout=20_000)
    expect(page.locator('#robots button[data-robot="hbs3"]')).to_contain_text("offline")
    expect(page.locator('#robot[data-robot="hbs2"]')).to_be_visible()
    # the robot's sensors arrive live: the obstacle the scenario put on its left
    expect(page.locator('#telemetry tr[data-key="/sensors/range/left_mm"]')).to_contain_text(
        "250", timeout=20_000
    )
    expect(page.locator('#devices li[data-key="/devices/servos/ok"]')).to_have_text("servos: ok")

    page.select_option("#type", "say")
    page.fill("#arg-text", "Hello from the page")
    page.click("#send button[type=submit]")
    row = page.locator("#commands tbody tr").first
    expect(row).to_contain_text("Hello from the page")
    expect(row).to_have_attribute("data-state", "SUCCEEDED", timeout=20_000)


def test_a_command_the_robot_refuses_ends_failed_with_its_reason(
    page: Page, lab: dict[str, Any]
) -> None:
    log_in(page, lab["url"], lab["token"])
    expect(page.locator('#robot[data-robot="hbs2"]')).to_be_visible()
    page.select_option("#type", "move")
    page.fill("#arg-joint", "tail")
    page.fill("#arg-angle_deg", "500")
    page.click("#send button[type=submit]")
    expect(page.locator("#send-error")).to_have_text("angle_deg: at most 180")
    expect(page.locator("#commands tbody tr")).to_have_count(0)  # nothing was sent

    page.fill("#arg-angle_deg", "20")
    page.click("#send button[type=submit]")
    row = page.locator("#commands tbody tr").first
    expect(row).to_have_attribute("data-state", "FAILED", timeout=20_000)
    expect(row).to_contain_text("tail")  # the robot's reason names the joint


def test_a_command_for_a_robot_that_is_off_waits_and_can_be_canceled(
    page: Page, lab: dict[str, Any]
) -> None:
    log_in(page, lab["url"], lab["token"])
    expect(page.locator('#robot[data-robot="hbs2"]')).to_be_visible()  # chosen first
    page.locator('#robots button[data-robot="hbs3"]').click()
    expect(page.locator('#robot[data-robot="hbs3"]')).to_be_visible()
    expect(page.locator("#robot-status")).to_contain_text("Offline")
    page.select_option("#type", "led")
    page.fill("#arg-color", "pink")
    page.click("#send button[type=submit]")
    row = page.locator("#commands tbody tr").first
    expect(row).to_have_attribute("data-state", "QUEUED")
    row.locator("button.cancel").click()
    expect(row).to_have_attribute("data-state", "CANCELED")
    expect(row.locator("button.cancel")).to_have_count(0)


def test_the_page_fits_a_tablet_held_upright_and_axe_finds_nothing_serious(
    browser: Browser, lab: dict[str, Any], accessibility: Callable[[Page], list[str]]
) -> None:
    context = browser.new_context(viewport={"width": 768, "height": 1024}, has_touch=True)
    page = context.new_page()
    try:
        page.goto(lab["url"])
        assert accessibility(page) == []  # the login form
        log_in(page, lab["url"], lab["token"])
        expect(page.locator("#robot")).to_be_visible()
        assert page.evaluate("document.documentElement.scrollWidth") <= 768
        box = page.locator("#send button[type=submit]").bounding_box()
        assert box is not None and box["height"] >= 44  # a finger can hit it
        assert accessibility(page) == []  # a robot watched, its commands and sensors
    finally:
        context.close()


@pytest.fixture
def watchers(tmp_path: Path, start_service: Callable[..., Any]) -> dict[str, Any]:
    """hbs2 (switched off) with a command ana queued and a force it last pushed; tess (a
    therapist) and vic (a viewer) may see it."""
    running = start_service(Settings(db_url=f"sqlite:///{tmp_path / 'c.db'}"))
    store = running.store
    ana = store.directory.add_operator("ana")
    robot = store.directory.authenticate(store.directory.add_robot("hbs2", operator="ana"))
    assert robot is not None
    tokens = {
        "tess": store.directory.add_operator("tess", role="therapist"),
        "vic": store.directory.add_operator("vic", role="viewer"),
    }
    for person in tokens:
        store.directory.grant(person, "hbs2")
    store.ledger.submit(robot.id, "say", {"text": "Hello"})
    store.telemetry.put(robot.id, {"/sensors/force/left_n": 3.5})
    return {"url": running.url, "ana": ana, **tokens}


def test_a_therapist_follows_commands_and_sensors_but_is_offered_no_command(
    page: Page, watchers: dict[str, Any]
) -> None:
    log_in(page, watchers["url"], watchers["tess"])
    expect(page.locator("#who")).to_have_text("tess (therapist)")
    row = page.locator("#commands tbody tr").first
    expect(row).to_have_attribute("data-state", "QUEUED")
    expect(row.locator("button.cancel")).to_have_count(0)
    expect(page.locator("#send")).to_be_hidden()
    expect(page.locator("#read-only")).to_have_text(
        "You can follow this robot's commands; your role, therapist, does not send or cancel them."
    )
    expect(page.locator('#telemetry tr[data-key="/sensors/force/left_n"]')).to_contain_text("3.5")


def test_a_viewer_sees_commands_and_no_sensor_value(page: Page, watchers: dict[str, Any]) -> None:
    log_in(page, watchers["url"], watchers["vic"])
    expect(page.locator("#commands tbody tr").first).to_contain_text("Hello")
    expect(page.locator("#send")).to_be_hidden()
    expect(page.locator("#sensors")).to_be_hidden()
    expect(page.locator("#sensors-hidden")).to_have_text(
        "Sensor values are not shown to your role, viewer: they are a child's data."
    )
    assert "3.5" not in page.content()
