"""The robot's link to the cloud service (``vest run --cloud URL --token-file FILE``).

Four workers, none of them in a tick:
- the *poller* long-polls ``GET /robot/commands/next``, stages each command on
  ``/iot/inbox`` for the iot_command tree, and backs off (0.5 s doubling to 30 s) while the
  service cannot be reached. A ``press`` (a therapist's, on the cloud's page) goes to the
  buttons at once (:class:`~engine.view.cloud_session.CloudSession`), also while
  another command is carried out: the robot then long-polls for presses alone;
- the *reporter* sends each result (``report``, the :class:`IotResults` service) until the
  service has it, in order, retrying the same way;
- two pushes (:class:`~engine.services.cloud_push.Push`, each on its
  :class:`~engine.periodic.Periodic`): the sensor and device keys about once a second, the
  latest values as the scheduler committed them (:class:`TelemetrySnapshot`, a reader of
  the consent gate's ``sent`` exit: readings only with the person's consent); and the
  session's view, when it changed, four times a second. A push that fails is logged (once
  per streak) and counted (``telemetry_failures``).

A command's result leaves the robot only when the consent gate lets it
(:meth:`~engine.privacy.consent_gate.ConsentGate.lets_result_out`): a read's values
without the person's consent are reported FAILED, saying why.

While the robot carries a command out it tells the service so every few seconds; when the
operator has canceled it meanwhile, the command's id is staged on ``/iot/canceled``: the
tree carrying it out stops, and its result is not reported (the command ended CANCELED).

A command is carried out once: finished ids and their results are kept in a small file
(``done_file``), so a command delivered again (its lease ran out, or the robot restarted)
is answered with the result it had, not carried out twice. A damaged file is set aside
(named in the log) and, since the robot can no longer tell what it already did, a command
delivered again is refused (reported FAILED with why) rather than risk running it twice.
"""

from __future__ import annotations

import logging
import threading
from pathlib import Path
from typing import Any

import requests

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import IOT_CANCELED, IOT_INBOX, NOTHING, Carries
from engine.clock import Clock
from engine.periodic import Periodic
from engine.privacy.consent import without_record
from engine.privacy.consent_gate import RESULT_WITHHELD, ConsentGate, Exit
from engine.services.cloud_push import NO_BOARD, PRESS, Push, SessionShown, json_object, positive_s
from engine.services.cloud_reports import FIRST_BACKOFF_S, MAX_BACKOFF_S, Reporter
from engine.services.done_commands import DoneCommands
from engine.services.jobs import ImmediateJob, Job
from engine.services.telemetry import TelemetrySnapshot
from engine.session.events import KeyChanged
from engine.session.json_values import json_value
from engine.session.stream import SessionStream

log = logging.getLogger(__name__)
TELEMETRY_EVERY_S = 1.0
SESSION_EVERY_S = 0.25
"""How often the session's view is pushed, when it changed (the cloud page's lag)."""
BUSY_POLL_S = 1.0
"""While a command is carried out the robot long-polls for presses alone, this long at a
time: the next command is taken at most this late after the last one is reported."""
BUSY_AT_MOST_S = 65.0
"""The robot takes one command at a time: the next long-poll waits until the one taken is
reported, or this long (CarryOut gives up on a command after 60 s), so a command that waits
in the service stays QUEUED, and an operator can still cancel it. Meanwhile the robot
extends the lease of the one it carries out three times a lease (``lease_s`` comes with
the command), so the service neither delivers it again nor shows it QUEUED."""
DEFAULT_LEASE_S = 30.0
TOO_LATE = "dropped: the service did not confirm it in time (a press is never carried out late)"
PROGRESS_EVERY_S = 2.0
"""How often the robot tells the service it is still at a command (at most a third of
the lease): an operator's cancel stops the robot within this."""
PROGRESS_AT_MOST_EVERY_S = 0.1
"""However short a lease the service gives, the robot says it is still at a command at most
ten times a second (a lease of 1 ms would otherwise be a storm of requests)."""


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
        self.gate = ConsentGate(without_record(""), Exit.SENT)
        """What may leave the robot (until bound: nothing of anyone)."""
        self.telemetry = TelemetrySnapshot()
        self.bad_replies = 0
        """Replies to a poll that were not a command (not JSON, not the contract's)."""
        self._replies_bad = False
        self._canceled: set[str] = set()  # canceled by the operator while carried out
        self._reports = Reporter(self.http, self.api, clock, self._unreachable)
        self._stop = clock.event()
        self._poller: threading.Thread | None = None
        self._telemetry_push = Push(
            self.http, f"{self.api}/robot/telemetry", "telemetry", self._telemetry_body
        )
        self.session: SessionShown | None = None
        """The session as the cloud's page shows it, and its presses (bound)."""
        self._session_push = Push(
            self.http, f"{self.api}/robot/session", "the session's view", self._session_body
        )
        self._pushes = [
            Periodic(clock, TELEMETRY_EVERY_S, self._telemetry_push.once, name="cloud-telemetry"),
            Periodic(clock, SESSION_EVERY_S, self._session_push.once, name="cloud-session"),
        ]
        self._from_cloud: set[str] = set()  # received, being carried out
        self._carrying_out = threading.Lock()
        self._idle = clock.event()
        self._idle.set()
        self._lease_s = DEFAULT_LEASE_S
        self._busy_until_s = self._extend_at_s = 0.0
        self.reachable = False

    def bind(
        self,
        blackboard: Blackboard,
        sent: SessionStream,
        gate: ConsentGate,
        session: SessionShown | None = None,
    ) -> None:
        """The blackboard commands are staged on; ``sent``, the consent gate's exit off
        the robot, whose committed sensor and device values are pushed as telemetry; and
        ``gate``, which says whether a command's result may leave; ``session``: the view
        the cloud's page shows (a reader of ``sent`` from the session's start), and where
        its presses go."""
        self.blackboard = blackboard
        self.gate = gate
        self.telemetry_from(sent)
        if session is not None:
            self.session = session
            self._session_push.failed = session.forget_sent

    def telemetry_from(self, sent: SessionStream) -> None:
        """Push the sensor and device values ``sent`` tells as committed."""
        sent.subscribe(self.telemetry, (KeyChanged.kind,))

    def start(self) -> None:
        for push in self._pushes:
            push.start()
        self._reports.start()
        self._poller = threading.Thread(target=self._poll, name="cloud-poll", daemon=True)
        self._poller.start()

    def stop(self) -> None:
        """Stop polling and pushing (the last view says the session ended); reports still
        queued get a few seconds to be sent. A long-poll in flight is left to end by
        itself: a command it claims now is delivered again once its lease runs out."""
        self._stop.set()
        for push in self._pushes:
            push.stop()
        if self.session is not None:  # the page stops offering what the robot no longer does
            self.session.end()
            self._session_push.once()
        self._reports.stop()
        if self._poller is not None:
            self._poller.join(timeout=0.5)

    # -- IotResults ------------------------------------------------------------------------
    def report(
        self, command_id: str, status: str, result: Any = None, *, carries: Carries = NOTHING
    ) -> Job:
        """Queue the report (it is sent, and retried, by the reporter); done at once. A
        command that did not come from the cloud (a scenario's, say) is not reported there;
        a result made from ``carries`` of a person goes only with their consent."""
        report = {"status": status.upper(), "result": json_value(result)}
        if not self.gate.lets_result_out(result, carries):
            report = {"status": "FAILED", "result": {"error": RESULT_WITHHELD}}
        settled = self._settle(command_id, report)
        if settled is not None:
            self._reports.put(command_id, settled)
        return ImmediateJob()

    def _settle(self, command_id: str, report: dict[str, Any]) -> dict[str, Any] | None:
        """Keep ``report`` as the command's end here; the report the service is to get,
        None when none (a command not from the cloud, or one the operator canceled)."""
        with self._carrying_out:
            if command_id not in self._from_cloud:
                log.debug("command %s did not come from the cloud; not reported there", command_id)
                return None
            canceled = command_id in self._canceled
            self._canceled.discard(command_id)
            if canceled:  # it ended CANCELED at the service; that is its end here too
                report = {"status": "CANCELED", "result": None}
            self.done.add(command_id, report)  # a delivery again is answered from here on
            self._from_cloud.discard(command_id)
            if not self._from_cloud:
                self._idle.set()
        return None if canceled else report

    def _press(self, command_id: str, args: dict[str, Any]) -> None:
        """A press from the cloud's page, checked here, then confirmed with the service
        before it is carried out: the service refuses a press past its 2 s, so one that
        reached the robot late is dropped, never carried out late."""
        if self.session is None:
            status, result, press = "FAILED", {"error": NO_BOARD}, None
        else:
            status, result, press = self.session.press(args)
        report = {"status": status, "result": result}
        if press is None:  # refused here: reported as any command is
            self.report(command_id, status, result)
            return
        confirmed = self._reports.confirm(command_id, report)
        if not confirmed:
            log.warning("a press from the cloud came too late (or unconfirmed): dropped")
            report = {"status": "FAILED", "result": {"error": TOO_LATE}}
        self._settle(command_id, report)  # the service has it, or has it TIMED_OUT
        if confirmed:
            press()

    # -- workers -----------------------------------------------------------------------------
    def _backoff(self, delay_s: float) -> float:
        self.clock.wait(self._stop, delay_s)
        return min(delay_s * 2, MAX_BACKOFF_S)

    def _poll(self) -> None:
        delay_s = FIRST_BACKOFF_S
        while not self._stop.is_set():
            params: dict[str, Any] = {"wait_s": self.wait_s}
            if not self._idle.is_set():  # one command at a time; presses meanwhile
                left_s = self._while_busy()
                if left_s is None:
                    continue
                params = {"wait_s": min(self.wait_s, left_s, BUSY_POLL_S), "only": PRESS}
            try:
                answer = self.http.get(
                    f"{self.api}/robot/commands/next",
                    params=params,
                    timeout=params["wait_s"] + 10.0,
                )
            except requests.RequestException as error:
                self._unreachable(error)
                delay_s = self._backoff(delay_s)
                continue
            if answer.status_code == 204:
                self.reachable, delay_s = True, FIRST_BACKOFF_S
                self._replies_bad = False  # the next streak of bad replies is logged again
                continue
            if answer.status_code != 200:
                log.warning(
                    "the cloud answered %s to a poll: %s", answer.status_code, answer.text[:200]
                )
                delay_s = self._backoff(delay_s)
                continue
            command = self._command_in(answer)
            if command is None:  # a captive portal, a proxy's page: not the service
                delay_s = self._backoff(delay_s)
                continue
            self.reachable, delay_s = True, FIRST_BACKOFF_S
            self._received(command)

    def _command_in(self, answer: requests.Response) -> dict[str, Any] | None:
        """The command a 200 reply carries, or None for a reply that is not one (counted in
        ``bad_replies``, logged once per streak): a captive portal's page, a proxy's."""
        command = json_object(answer)
        if (
            command is not None
            and isinstance(command.get("id"), str)
            and isinstance(command.get("type"), str)
            and isinstance(command.get("args", {}), dict)
        ):
            self._replies_bad = False
            return command
        self.bad_replies += 1
        if not self._replies_bad:
            log.warning(
                "the cloud's reply to a poll is not a command (%s: %.80r); the robot asks "
                "again with back-off",
                answer.headers.get("content-type", "no content type"),
                answer.text,
            )
        self._replies_bad = True
        self.reachable = False
        return None

    def _received(self, command: dict[str, Any]) -> None:
        command_id = str(command.get("id"))
        with self._carrying_out:  # a report between these checks would let it run twice
            earlier = self.done.get(command_id)
            running = command_id in self._from_cloud
            pressed = command.get("type") == PRESS
            if earlier is None and not running and self.blackboard is not None:
                self._from_cloud.add(command_id)
                if not pressed:  # a press is carried out at once, beside any other
                    self._idle.clear()
                    self._lease_s = positive_s(command.get("lease_s"), DEFAULT_LEASE_S)
                    self._busy_until_s = self.clock.now() + BUSY_AT_MOST_S
                    self._extend_at_s = self.clock.now() + self._extend_every_s()
        if earlier is not None:  # delivered again: answer as before, never twice
            if earlier.get("status") != "CANCELED":  # the service knows it ended so
                self._reports.put(command_id, earlier)
            return
        if self._unsure_if_done(command, command_id, running):
            return
        if running:  # delivered again while still being carried out
            log.debug("command %s is still being carried out; its report will follow", command_id)
            return
        if pressed:
            self._press(command_id, command.get("args") or {})
        elif self.blackboard is not None:
            self.blackboard.stage_event(
                IOT_INBOX,
                {"id": command_id, "type": command.get("type"), "args": command.get("args") or {}},
            )

    def _unsure_if_done(self, command: dict[str, Any], command_id: str, running: bool) -> bool:
        """A command delivered again after the record of finished commands was damaged
        may have been carried out already: it is refused (reported FAILED with why)."""
        delivered = command.get("deliveries")
        again = isinstance(delivered, int) and delivered > 1
        if self.done.damaged is None or running or not again:
            return False
        with self._carrying_out:
            self._from_cloud.discard(command_id)
            if not self._from_cloud:
                self._idle.set()
        why = (
            f"not carried out again: the robot's record of finished commands was damaged "
            f"(kept as {self.done.damaged.name}), so it cannot tell whether it already did it"
        )
        log.warning("command %s delivered again: %s", command_id, why)
        report = {"status": "FAILED", "result": {"error": why}}
        self.done.add(command_id, report)
        self._reports.put(command_id, report)
        return True

    def _while_busy(self) -> float | None:
        """While a command is carried out: extend its lease when due, and give up waiting
        for its report after BUSY_AT_MOST_S (a robot without the iot_command tree must not
        stop taking commands for good). Seconds until the next of these; None when the
        robot takes the next command now."""
        now_s = self.clock.now()
        if now_s >= self._busy_until_s:
            log.warning("no report after %.0f s; taking the next command", BUSY_AT_MOST_S)
            self._idle.set()
            return None
        if now_s >= self._extend_at_s:
            self._extend_leases()
            self._extend_at_s = now_s + self._extend_every_s()
        return max(0.0, min(self._busy_until_s, self._extend_at_s) - now_s)

    def _extend_every_s(self) -> float:
        return max(min(self._lease_s / 3, PROGRESS_EVERY_S), PROGRESS_AT_MOST_EVERY_S)

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
            # a reply that is not the command (a proxy's page): asked again at the next turn
            reply = json_object(answer) if answer.status_code == 200 else None
            if reply is not None and reply.get("state") == "CANCELED":
                self._cancel(command_id)

    def _cancel(self, command_id: str) -> None:
        """The operator canceled a command the robot is carrying out: the tree carrying it
        out is told to stop (``/iot/canceled``), and no result is reported."""
        with self._carrying_out:
            if command_id not in self._from_cloud or command_id in self._canceled:
                return
            self._canceled.add(command_id)
        log.info("command %s was canceled by the operator; the robot stops it", command_id)
        if self.blackboard is not None:
            self.blackboard.stage_event(IOT_CANCELED, command_id)

    def push_telemetry(self) -> bool:
        """Push the latest committed sensor and device values once; False when the push
        failed (counted in ``telemetry_failures``, logged once per streak: the next push
        carries the latest values anyway)."""
        return self._telemetry_push.once()

    @property
    def telemetry_failures(self) -> int:
        """Pushes of telemetry that failed (the service unreachable or refusing)."""
        return self._telemetry_push.failures

    def _telemetry_body(self) -> dict[str, Any] | None:
        values = self.telemetry.take()
        return {"values": values} if values else None

    def _session_body(self) -> dict[str, Any] | None:
        view = self.session.changed_view() if self.session is not None else None
        return {"view": view} if view is not None else None

    def _unreachable(self, error: Exception) -> None:
        if self.reachable:
            log.warning("the cloud cannot be reached (%s); the robot goes on and retries", error)
        self.reachable = False
