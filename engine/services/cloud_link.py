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
TELEMETRY_PREFIXES = (SENSORS_PREFIX, DEVICES_PREFIX)
DONE_KEPT = 1000


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
        self._reports.put((command_id, report))
        return ImmediateJob()

    # -- workers -----------------------------------------------------------------------------
    def _backoff(self, delay_s: float) -> float:
        self.clock.wait(self._stop, delay_s)
        return min(delay_s * 2, MAX_BACKOFF_S)

    def _poll(self) -> None:
        delay_s = FIRST_BACKOFF_S
        while not self._stop.is_set():
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
