"""The robot's reports to the cloud service: what became of each command it took.

Reports go in order, each retried with back-off (0.5 s doubling to 30 s) until the service
has it; once the robot stops, the reports still queued get one try each (a command whose
report is lost is delivered again later and answered from the record of finished ones). A
press of a button asks the service first (:meth:`Reporter.confirm`): the service refuses a
report past the command's timeout, so a press that reached the robot too late is dropped.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from typing import Any

import requests

from engine.clock import Clock

log = logging.getLogger("engine.services.cloud_link")
FIRST_BACKOFF_S, MAX_BACKOFF_S = 0.5, 30.0
STOP_WAIT_S = 5.0
"""How long (real seconds) stopping waits for the reports still queued."""
Report = dict[str, Any]


class Reporter:
    """Sends reports to ``api`` with ``http``; ``unreachable`` is told of each error."""

    def __init__(
        self,
        http: requests.Session,
        api: str,
        clock: Clock,
        unreachable: Callable[[Exception], None],
    ) -> None:
        self.http, self.api, self.clock, self.unreachable = http, api, clock, unreachable
        self._queue: queue.Queue[tuple[str, Report] | None] = queue.Queue()
        self._stop = clock.event()
        self._thread: threading.Thread | None = None

    def put(self, command_id: str, report: Report) -> None:
        """Send ``report`` of ``command_id`` after those queued before it."""
        self._queue.put((command_id, report))

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="cloud-report", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """The reports still queued get one try each (STOP_WAIT_S at most in all)."""
        self._stop.set()
        self._queue.put(None)
        if self._thread is not None:
            self._thread.join(timeout=STOP_WAIT_S)

    def confirm(self, command_id: str, report: Report) -> bool:
        """Send ``report`` now, once: True only when the service took it (False: it refused
        it, the command having timed out, or it could not be reached)."""
        return self._send(command_id, report) == 200

    def _run(self) -> None:
        delay_s = FIRST_BACKOFF_S
        while (item := self._queue.get()) is not None:
            while self._send(*item) is None and not self._stop.is_set():
                self.clock.wait(self._stop, delay_s)
                delay_s = min(delay_s * 2, MAX_BACKOFF_S)
            delay_s = FIRST_BACKOFF_S

    def _send(self, command_id: str, report: Report) -> int | None:
        """One try: the service's answer, None when it is to be tried again."""
        try:
            answer = self.http.post(
                f"{self.api}/robot/commands/{command_id}/result", json=report, timeout=10.0
            )
        except requests.RequestException as error:
            self.unreachable(error)
            return None
        if answer.status_code >= 500:
            return None
        if answer.status_code != 200:  # 404 or 409: the service knows better; said once
            log.warning("report for %s: %s %s", command_id, answer.status_code, answer.text[:200])
        return answer.status_code
