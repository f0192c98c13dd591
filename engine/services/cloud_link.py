"""The robot's link to the cloud service (``vest run --cloud URL --token-file FILE``).

Three worker threads, none of them in a tick:
- the *poller* long-polls ``GET /robot/commands/next``, stages each command on
  ``/iot/inbox`` for the iot_command tree, and backs off (0.5 s doubling to 30 s) while the
  service cannot be reached;
- the *reporter* sends each result (``report``, the :class:`IotResults` service) until the
  service has it, in order, retrying the same way;
- the *telemetry* thread pushes the blackboard's sensor and device keys about once a second.

A command is carried out once: finished ids and their results are kept in a small file
(``done_file``), so a command delivered again (its lease ran out, or the robot restarted)
is answered with the result it had, not carried out twice.
"""

from __future__ import annotations

import json
import logging
import math
import queue
import threading
from pathlib import Path
from typing import Any

import requests

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import DEVICES_PREFIX, IOT_INBOX, SENSORS_PREFIX
from engine.blackboard.events import EventLog
from engine.clock import Clock
from engine.services.jobs import ImmediateJob, Job

log = logging.getLogger(__name__)
FIRST_BACKOFF_S, MAX_BACKOFF_S = 0.5, 30.0
TELEMETRY_EVERY_S = 1.0
BUSY_AT_MOST_S = 65.0
"""The robot takes one command at a time: the next long-poll waits until the one taken is
reported, or this long (CarryOut gives up on a command after 60 s), so a command that waits
in the service stays QUEUED, and an operator can still cancel it. Meanwhile the robot
extends the lease of the one it carries out three times a lease (``lease_s`` comes with
the command), so the service neither delivers it again nor shows it QUEUED."""
DEFAULT_LEASE_S = 30.0
TELEMETRY_PREFIXES = (SENSORS_PREFIX, DEVICES_PREFIX)
DONE_KEPT = 1000


def _positive(value: Any, default: float) -> float:
    """``value`` as a positive number of seconds, else ``default``."""
    if isinstance(value, int | float) and not isinstance(value, bool) and value > 0:
        return float(value)
    return default


def _json_safe(value: Any) -> Any:
    """Numbers that JSON cannot carry (NaN, infinity) as None; containers walked; an
    event key as its latest event's value (None before the first)."""
    if isinstance(value, EventLog):
        return _json_safe(value.latest.value) if value.latest is not None else None
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(v) for v in value]
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


class DoneCommands:
    """Finished command ids and their reports, kept in a JSON file across restarts."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._done: dict[str, dict[str, Any]] = {}
        try:
            loaded = json.loads(path.read_text(encoding="utf-8"))
            if isinstance(loaded, dict):
                self._done = {str(k): v for k, v in loaded.items() if isinstance(v, dict)}
        except (OSError, ValueError):
            pass  # none yet, or unreadable: start afresh (the ledger refuses a contrary report)
        self._lock = threading.Lock()

    def get(self, command_id: str) -> dict[str, Any] | None:
        with self._lock:
            return self._done.get(command_id)

    def add(self, command_id: str, report: dict[str, Any]) -> None:
        with self._lock:
            self._done[command_id] = report
            while len(self._done) > DONE_KEPT:
                self._done.pop(next(iter(self._done)))
            text = json.dumps(self._done)
        try:
            temporary = self.path.with_suffix(".tmp")
            temporary.write_text(text, encoding="utf-8")
            temporary.replace(self.path)
        except OSError as error:
            log.warning("cannot keep finished commands in %s: %s", self.path, error)


class CloudLink:
    """Implements :class:`~engine.services.interfaces.IotResults` against the service."""

    def __init__(
        self,
        url: str,
        token: str,
        clock: Clock,
        *,
        done_file: Path,
        wait_s: float = 25.0,
        http: requests.Session | None = None,
    ) -> None:
        self.api = url.rstrip("/") + "/api/v1"
        self.clock = clock
        self.wait_s = wait_s
        self.http = http or requests.Session()
        self.http.headers["Authorization"] = f"Bearer {token}"
        self.done = DoneCommands(done_file)
        self.blackboard: Blackboard | None = None
        self._reports: queue.Queue[tuple[str, dict[str, Any]] | None] = queue.Queue()
        self._stop = clock.event()
        self._threads: list[threading.Thread] = []
        self._from_cloud: set[str] = set()  # received, being carried out
        self._carrying_out = threading.Lock()
        self._idle = clock.event()
        self._idle.set()
        self._lease_s = DEFAULT_LEASE_S
        self.reachable = False

    def bind(self, blackboard: Blackboard) -> None:
        """The blackboard commands are staged on and telemetry is read from."""
        self.blackboard = blackboard

    def start(self) -> None:
        for name, target in (
            ("cloud-poll", self._poll),
            ("cloud-report", self._send_reports),
            ("cloud-telemetry", self._push_telemetry),
        ):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            self._threads.append(thread)

    def stop(self) -> None:
        """Stop polling and pushing; reports still queued get a few seconds to be sent. A
        long-poll in flight is left to end by itself: a command it claims now is
        delivered again once its lease runs out."""
        self._stop.set()
        self._reports.put(None)
        for thread in self._threads:
            thread.join(timeout=5.0 if thread.name == "cloud-report" else 0.5)

    # -- IotResults ------------------------------------------------------------------------
    def report(self, command_id: str, status: str, result: Any = None) -> Job:
        """Queue the report (it is sent, and retried, by the reporter); done at once. A
        command that did not come from the cloud (a scenario's, say) is not reported there."""
        report = {"status": status.upper(), "result": _json_safe(result)}
        with self._carrying_out:
            if command_id not in self._from_cloud:
                log.debug("command %s did not come from the cloud; not reported there", command_id)
                return ImmediateJob()
            self.done.add(command_id, report)  # a delivery again is answered from here on
            self._from_cloud.discard(command_id)
            if not self._from_cloud:
                self._idle.set()
        self._reports.put((command_id, report))
        return ImmediateJob()

    # -- workers -----------------------------------------------------------------------------
    def _backoff(self, delay_s: float) -> float:
        self.clock.wait(self._stop, delay_s)
        return min(delay_s * 2, MAX_BACKOFF_S)

    def _poll(self) -> None:
        delay_s = FIRST_BACKOFF_S
        while not self._stop.is_set():
            if not self._idle.is_set():  # one command at a time
                self._wait_idle()
                continue
            try:
                answer = self.http.get(
                    f"{self.api}/robot/commands/next",
                    params={"wait_s": self.wait_s},
                    timeout=self.wait_s + 10.0,
                )
            except requests.RequestException as error:
                self._unreachable(error)
                delay_s = self._backoff(delay_s)
                continue
            if answer.status_code == 204:
                self.reachable, delay_s = True, FIRST_BACKOFF_S
                continue
            if answer.status_code != 200:
                log.warning(
                    "the cloud answered %s to a poll: %s", answer.status_code, answer.text[:200]
                )
                delay_s = self._backoff(delay_s)
                continue
            self.reachable, delay_s = True, FIRST_BACKOFF_S
            self._received(answer.json())

    def _received(self, command: dict[str, Any]) -> None:
        command_id = str(command.get("id"))
        with self._carrying_out:  # a report between these checks would let it run twice
            earlier = self.done.get(command_id)
            running = command_id in self._from_cloud
            if earlier is None and not running and self.blackboard is not None:
                self._from_cloud.add(command_id)
                self._idle.clear()
                self._lease_s = _positive(command.get("lease_s"), DEFAULT_LEASE_S)
        if earlier is not None:  # delivered again: answer as before, never twice
            self._reports.put((command_id, earlier))
            return
        if running:  # delivered again while still being carried out
            log.debug("command %s is still being carried out; its report will follow", command_id)
            return
        if self.blackboard is not None:
            self.blackboard.stage_event(
                IOT_INBOX,
                {"id": command_id, "type": command.get("type"), "args": command.get("args") or {}},
            )

    def _wait_idle(self) -> None:
        """Until the command being carried out is reported (or BUSY_AT_MOST_S passed: a
        robot without the iot_command tree must not stop taking commands for good)."""
        deadline_s = self.clock.now() + BUSY_AT_MOST_S
        extend_every_s = self._lease_s / 3
        extend_at_s = self.clock.now() + extend_every_s
        while not self._idle.is_set() and not self._stop.is_set():
            now_s = self.clock.now()
            if now_s >= deadline_s:
                log.warning("no report after %.0f s; taking the next command", BUSY_AT_MOST_S)
                self._idle.set()
                return
            if now_s >= extend_at_s:
                self._extend_leases()
                extend_at_s = now_s + extend_every_s
            # looks at the stop flag at least each second
            self.clock.wait(self._idle, min(deadline_s - now_s, extend_at_s - now_s, 1.0))

    def _extend_leases(self) -> None:
        """Tells the service the robot is still carrying its commands out (one that fails is
        tried again at the next turn; a lease that ran out meanwhile is taken back then)."""
        with self._carrying_out:
            running = sorted(self._from_cloud)
        for command_id in running:
            try:
                answer = self.http.post(
                    f"{self.api}/robot/commands/{command_id}/progress", timeout=5.0
                )
            except requests.RequestException as error:
                self._unreachable(error)
                continue
            if answer.status_code == 200 and answer.json().get("state") == "CANCELED":
                log.info("command %s was canceled while the robot carried it out", command_id)

    def _send_reports(self) -> None:
        delay_s = FIRST_BACKOFF_S
        while True:
            item = self._reports.get()
            if item is None:
                return
            command_id, report = item
            while not self._stop.is_set():
                try:
                    answer = self.http.post(
                        f"{self.api}/robot/commands/{command_id}/result", json=report, timeout=10.0
                    )
                except requests.RequestException as error:
                    self._unreachable(error)
                    delay_s = self._backoff(delay_s)
                    continue
                if answer.status_code >= 500:
                    delay_s = self._backoff(delay_s)
                    continue
                if answer.status_code != 200:  # 404 or 409: the service knows better; said once
                    log.warning(
                        "report for %s: %s %s", command_id, answer.status_code, answer.text[:200]
                    )
                delay_s = FIRST_BACKOFF_S
                break

    def _push_telemetry(self) -> None:
        while not self.clock.wait(self._stop, TELEMETRY_EVERY_S):
            board = self.blackboard
            if board is None:
                continue
            try:
                values = {
                    key: _json_safe(value)
                    for key, value in board.snapshot().items()
                    if key.startswith(TELEMETRY_PREFIXES)
                }
                self.http.post(f"{self.api}/robot/telemetry", json={"values": values}, timeout=5.0)
            except (requests.RequestException, RuntimeError):
                continue  # the next push carries the latest values anyway

    def _unreachable(self, error: Exception) -> None:
        if self.reachable:
            log.warning("the cloud cannot be reached (%s); the robot goes on and retries", error)
        self.reachable = False
