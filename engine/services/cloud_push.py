"""The robot's exchanges with the cloud service: one kind of push (a JSON body POSTed to one
endpoint every so often, when there is something to push: the telemetry, the session's
view), and how the robot reads the service's replies.

A push that fails (the service unreachable, or answering an error) is counted in
``failures`` and logged once per streak, and once when pushes go through again: the next
push carries the latest anyway, so nothing is queued.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any, Protocol

import requests

log = logging.getLogger("engine.services.cloud_link")
PUSH_TIMEOUT_S = 5.0
PRESS = "press"
"""The type of the cloud's command that presses one of the robot's buttons."""
NO_BOARD = "this robot runs no buttons (start it with vest run --buttons FILE)"


class SessionShown(Protocol):
    """The session as the cloud's page shows it, and where the page's presses go
    (:class:`engine.view.cloud_session.CloudSession`)."""

    def changed_view(self) -> dict[str, Any] | None:
        """The view when it changed since the last one returned, else None."""
        ...

    def forget_sent(self) -> None:
        """The last view did not reach the cloud: the next look returns it again."""
        ...

    def end(self) -> None:
        """The robot stops: the next view says the session ended."""
        ...

    def press(
        self, args: dict[str, Any]
    ) -> tuple[str, dict[str, Any], Callable[[], object] | None]:
        """Check a press (``{"button", "by"}``): its report's status and result, and what
        carries it out (None: refused, the result says why)."""
        ...


class Push:
    """POSTs ``take()`` (None: nothing to push now) to ``url`` with ``http``; ``what`` names
    it in the log; ``failed()`` is told of each push that did not go through."""

    def __init__(
        self,
        http: requests.Session,
        url: str,
        what: str,
        take: Callable[[], dict[str, Any] | None],
        failed: Callable[[], None] = lambda: None,
    ) -> None:
        self.http = http
        self.url = url
        self.what = what
        self.take = take
        self.failed = failed
        self.failures = 0
        self._failing = False

    def once(self) -> bool:
        """Push once, if there is something; False when the push failed."""
        body = self.take()
        if body is None:
            return True
        why = ""
        try:
            answer = self.http.post(self.url, json=body, timeout=PUSH_TIMEOUT_S)
            if answer.status_code >= 300:
                why = f"the service answered {answer.status_code}: {answer.text[:200]}"
        except requests.RequestException as error:
            why = str(error)
        if why:
            self.failures += 1
            self.failed()
            if not self._failing:
                log.warning("%s could not be pushed (%s); the robot retries", self.what, why)
            self._failing = True
            return False
        if self._failing:
            log.info("%s is pushed again after %d failures", self.what, self.failures)
            self._failing = False
        return True


def json_object(answer: requests.Response) -> dict[str, Any] | None:
    """The JSON object ``answer`` carries; None for anything else (not JSON, nested too
    deep to read, a list or a number): a peer's reply never ends the thread reading it."""
    try:
        body = answer.json()
    except (ValueError, RecursionError):
        return None
    return body if isinstance(body, dict) else None


def positive_s(value: Any, default: float) -> float:
    """``value`` as a positive number of seconds, else ``default``."""
    if isinstance(value, int | float) and not isinstance(value, bool) and value > 0:
        return float(value)
    return default
