"""The robot on a ROS 2 graph (``vest run --ros2 [ROUTER]``): a node named ``vest`` that
``rmw_zenoh`` nodes see as one of their own (:mod:`engine.interop.ros2_wire`), through
Zenoh's own Python binding (``eclipse-zenoh``) and ``rosbags``' ROS 2 types, with no ROS
installed. It publishes:

- each sensor, camera, speech and device key on ``/vest/<key>`` as ``std_msgs/Bool``,
  ``Float64`` or ``String`` (by the key's type in the catalogue; lists and objects as
  JSON text): ``/vest/sensors/force/left_n`` is a ``Float64`` in newtons;
- each tree's status changes on ``/vest/trees/<tree>/log`` as Nav2's
  ``nav2_msgs/BehaviorTreeLog`` (``uid``: the node's number in ``vest render`` plus one;
  ``node_name``: its path; IDLE, RUNNING, SUCCESS, FAILURE);
- the actions, their outcomes, the world's and the session's events on the topics of
  ``vest replay --to mcap`` (``/vest/actions``, ``/vest/actions/outcome``, ``/vest/world``,
  ``/vest/events``) as ``std_msgs/String`` holding the same JSON.

What leaves the robot follows the person's consent as the cloud's telemetry does: without
``cloud_telemetry``, the robot's own account only (statuses, actions, devices), never a
sensor reading nor a heard word; with it, what a recording of them would keep.

Commands, only when asked for (``--ros2-commands``: a ROS 2 graph has no accounts, so
anyone on it may then command the robot): a ``std_msgs/String`` on ``/vest/command``
holding ``{"type": "say"|"led"|"move"|"read", "args": {...}, "id": "..."}`` goes the cloud's
way, checked as the cloud checks it, then staged on ``/iot/inbox`` for the iot_command tree
(its checks, and the safety envelope, as for an operator's); how it ended comes back on
``/vest/command/result``. Never raw actuator access: a robot without the iot_command tree
carries nothing out.

A session reader: the scheduler's thread only hands each event over
(:class:`~engine.session.handoff.Handoff`); a thread beside it publishes.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import re
import threading
from typing import Any

import zenoh

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import DEVICES_PREFIX, IOT_INBOX, SENSORS_PREFIX, KeyCatalogue
from engine.blackboard.events import EventLog
from engine.clock import Clock
from engine.errors import ConfigError
from engine.interop.ros2_plan import Ros2Plan
from engine.interop.ros2_wire import (
    Endpoint,
    NodeName,
    Wire,
    attachment,
    publisher_gid,
    ros_name,
    ros_time,
    session_config,
)
from engine.interop.session_topics import NodePaths, live_message
from engine.privacy.consent import Consent
from engine.recording.kept_by_consent import VISION_PREFIX, KeptByConsent
from engine.remote_commands import COMMAND_TYPES, command_problem
from engine.services.telemetry import WITHHELD, carries_sensor_values, json_safe
from engine.session.events import (
    ActionEnded,
    ActionStarted,
    KeyChanged,
    NodeStatus,
    SessionEvent,
    TreeStarted,
)
from engine.session.handoff import Handoff

log = logging.getLogger(__name__)
CAPACITY = 50_000
"""Events the queue holds before it drops (seconds of the busiest session)."""
PUBLISHED_KEYS = (SENSORS_PREFIX, VISION_PREFIX, "/speech/", DEVICES_PREFIX)
COMMAND_TOPIC, RESULT_TOPIC = "/vest/command", "/vest/command/result"
STRING, BOOL, FLOAT = "std_msgs/msg/String", "std_msgs/msg/Bool", "std_msgs/msg/Float64"
TREE_LOG = "nav2_msgs/msg/BehaviorTreeLog"
AT_MOST_WAITING = 8
"""Commands from the graph carried out or waiting at once; more are refused (a flood)."""
WAITING_AT_MOST_S = 65.0
"""A command whose result has not come in this long is forgotten (CarryOut gives up after
60 s; a tree cut off never reports)."""
_COMMAND_ID = re.compile(r"[A-Za-z0-9_.:-]{1,64}")
BT_STATUS = {"INVALID": "IDLE", "RUNNING": "RUNNING", "SUCCESS": "SUCCESS", "FAILURE": "FAILURE"}


class Ros2Bridge:
    """Publishes the session on a ROS 2 graph, and takes commands from it when asked."""

    def __init__(
        self,
        plan: Ros2Plan,
        clock: Clock,
        epoch_offset_s: float,
        consent: Consent,
        catalogue: KeyCatalogue,
    ) -> None:
        """``plan``: where the graph is and whether commands are taken; ``epoch_offset_s``
        turns the clock's seconds into seconds since the epoch (ROS time)."""
        self.plan, self.clock, self.epoch_offset_s = plan, clock, epoch_offset_s
        self.catalogue = catalogue
        self.telemetry_allowed = consent.allows("cloud_telemetry")
        leaving = consent.covers if self.telemetry_allowed else consent.covers - {"sensors"}
        if not self.telemetry_allowed:
            leaving -= {"speech_text"}
        self._keeps = KeptByConsent(Consent(consent.person, frozenset(leaving)))
        self.node = NodeName("vest")
        self.wire = Wire()
        self.blackboard: Blackboard | None = None
        self._session: zenoh.Session | None = None
        self._zid = ""
        self._tokens: list[Any] = []  # liveliness tokens, kept while the bridge runs
        self._publishers: dict[str, tuple[Endpoint, Any, bytes]] = {}
        self._sequence: dict[str, int] = {}
        self._paths: NodePaths = {}
        self._statuses: dict[tuple[str, int, int], str] = {}
        self._waiting: dict[str, float] = {}  # command id -> when it was staged (clock s)
        self._lock = threading.Lock()  # publishers and waiting commands, two threads
        self._count = 0  # commands taken, for those sent without an id
        self._entities = 0  # the node's publishers and subscriptions, numbered
        self._handoff = Handoff("ros2", self._send, capacity=CAPACITY)

    # -- lifecycle -----------------------------------------------------------------------
    def start(self, blackboard: Blackboard) -> None:
        """Joins the graph (ConfigError for a router address or file Zenoh cannot use; a
        router not up yet is tried again by Zenoh meanwhile) and starts publishing."""
        self.blackboard = blackboard
        try:
            self._session = zenoh.open(session_config(self.plan.router, self.plan.config_file))
        except zenoh.ZError as error:
            why = _first_line(error)
            raise ConfigError(f"--ros2 {self.where}: Zenoh cannot use it ({why})") from None
        self._zid = str(self._session.zid())
        self._tokens.append(self._declare_token(self.node.token(self.plan.domain, self._zid)))
        if self.plan.commands:
            command = self.wire.endpoint(COMMAND_TOPIC, STRING)
            entity = self._next_entity()
            self._publisher(RESULT_TOPIC, STRING)  # declared now: a sender can wait for it
            self._tokens.append(
                self._session.declare_subscriber(command.key(self.plan.domain), self._command_in)
            )  # then its token: a node that sees the token finds the subscriber there
            token = command.token(self.plan.domain, self._zid, self.node, entity, "MS")
            self._tokens.append(self._declare_token(token))
        self._handoff.start()

    @property
    def where(self) -> str:
        return self.plan.config_file or self.plan.router

    def on_event(self, event: SessionEvent) -> None:
        """The scheduler's thread: queued, never waited for."""
        self._handoff.put(event)

    def stop(self) -> None:
        self._handoff.close()
        if self._session is not None:
            self._session.close()  # type: ignore[no-untyped-call]  # its tokens go: the graph sees the node leave
            self._session = None
        if self._handoff.dropped:
            log.warning("ros2: %d events were dropped", self._handoff.dropped)

    # -- publishing (the bridge's thread) --------------------------------------------------
    def _send(self, events: list[SessionEvent]) -> bool:
        logs: dict[str, list[dict[str, Any]]] = {}
        for event in events:
            if isinstance(event, ActionStarted) and event.action == "report":
                self._result(event)
            kept = self._keeps.kept(event)
            if kept is None:
                continue
            if (
                isinstance(kept, ActionStarted | ActionEnded)
                and not self.telemetry_allowed
                and carries_sensor_values(kept.args)
            ):  # a read's result, reported: not without consent
                kept = dataclasses.replace(kept, args={"result": WITHHELD})
            if isinstance(kept, TreeStarted):
                for node in kept.nodes:
                    self._paths[(kept.tree, kept.version, node.index)] = (node.path, node.type)
            elif isinstance(kept, NodeStatus):
                logs.setdefault(kept.tree, []).append(self._status_change(kept))
            elif isinstance(kept, KeyChanged):
                if kept.key.startswith(PUBLISHED_KEYS):
                    self._key(kept)
            else:
                found = live_message(kept, self._paths)
                if found is not None:
                    topic, _, message = found
                    self._publish(topic, STRING, {"data": json.dumps(message)}, kept.t_s)
        now_s = self.clock.now()
        for tree, changes in logs.items():
            stamp = ros_time(now_s + self.epoch_offset_s)
            topic = ros_name(f"/vest/trees/{tree}/log")
            self._publish(topic, TREE_LOG, {"timestamp": stamp, "event_log": changes}, now_s)
        with self._lock:
            lost = [key for key, at_s in self._waiting.items() if now_s - at_s > WAITING_AT_MOST_S]
            for command_id in lost:
                del self._waiting[command_id]
        for command_id in lost:
            why = f"no result in {WAITING_AT_MOST_S:.0f} s: is the iot_command tree running?"
            self._tell(command_id, "LOST", {"error": why})
        return True

    def _status_change(self, event: NodeStatus) -> dict[str, Any]:
        where = (event.tree, event.version, event.node)
        status = BT_STATUS.get(event.status, "IDLE")
        previous = self._statuses.get(where, "IDLE")
        self._statuses[where] = status
        path = self._paths.get(where, (f"n{event.node}", ""))[0]
        return {
            "timestamp": ros_time(event.t_s + self.epoch_offset_s),
            "node_name": path,
            "uid": min(event.node + 1, 0xFFFF),
            "previous_status": previous,
            "current_status": status,
        }

    def _key(self, event: KeyChanged) -> None:
        value = event.value
        if isinstance(value, EventLog):  # an event key: the event just told
            value = value.latest.value if value.latest is not None else None
        spec = self.catalogue.lookup(event.key)
        declared = spec.value_type if spec is not None else None
        topic = ros_name("/vest" + event.key)
        if declared is bool and isinstance(value, bool):
            self._publish(topic, BOOL, {"data": value}, event.t_s)
        elif declared is float and isinstance(value, int | float) and not isinstance(value, bool):
            self._publish(topic, FLOAT, {"data": float(value)}, event.t_s)
        elif declared is float and value is None:  # no reading: NaN, as ROS drivers say it
            self._publish(topic, FLOAT, {"data": float("nan")}, event.t_s)
        elif declared not in (bool, float):
            text = value if isinstance(value, str) else json.dumps(json_safe(value))
            self._publish(topic, STRING, {"data": text}, event.t_s)

    def _result(self, event: ActionStarted) -> None:
        """A command from the graph ended: its report, on the result topic."""
        command_id = str(event.args.get("id", ""))
        with self._lock:
            if self._waiting.pop(command_id, None) is None:
                return  # the cloud's, or a scenario's
        result = event.args.get("result")
        status = str(event.args.get("status", "")).upper()
        if not self.telemetry_allowed and carries_sensor_values(result):
            status, result = "FAILED", {"error": WITHHELD}
        self._tell(command_id, status, json_safe(result))

    def _publish(self, topic: str, typename: str, fields: dict[str, Any], at_s: float) -> None:
        try:
            payload = self.wire.encode(typename, fields)
        except Exception as error:  # a value the type cannot carry: the rest goes on
            log.warning("ros2: %s not sent (%s)", topic, error)
            return
        with self._lock:
            endpoint, publisher, gid = self._publisher(topic, typename)
            sequence = self._sequence[topic] = self._sequence.get(topic, 0) + 1
        source_ns = max(0, round((at_s + self.epoch_offset_s) * 1e9))
        try:
            publisher.put(payload, attachment=attachment(sequence, source_ns, gid))
        except zenoh.ZError as error:
            log.warning("ros2: %s not sent (%s)", endpoint.topic, _first_line(error))

    def _publisher(self, topic: str, typename: str) -> tuple[Endpoint, Any, bytes]:
        """The publisher of ``topic`` (declared, with its token, on first use; the lock
        held where another thread may publish too)."""
        found = self._publishers.get(topic)
        if found is not None:
            return found
        assert self._session is not None
        endpoint = self.wire.endpoint(topic, typename)
        entity = self._next_entity()
        domain = self.plan.domain
        publisher = self._session.declare_publisher(endpoint.key(domain))
        token = endpoint.token(domain, self._zid, self.node, entity, "MP")
        self._tokens.append(self._declare_token(token))
        found = self._publishers[topic] = (endpoint, publisher, publisher_gid(self._zid, entity))
        return found

    # -- commands (Zenoh's thread) ---------------------------------------------------------
    def _command_in(self, sample: zenoh.Sample) -> None:
        """A command from the graph: checked, then staged for the iot_command tree; a
        command that cannot be carried out is answered at once (REFUSED, with why)."""
        try:
            text = self.wire.decode(STRING, bytes(sample.payload.to_bytes())).data
            command = json.loads(text)
        except (ValueError, AttributeError) as error:
            self._refuse(None, f"not a std_msgs/String of JSON ({error})")
            return
        if not isinstance(command, dict):
            self._refuse(None, 'a command is a JSON object: {"type": "say", "args": {...}}')
            return
        given = command.get("id")
        if given is not None and not (isinstance(given, str) and _COMMAND_ID.fullmatch(given)):
            self._refuse(None, "id: up to 64 letters, digits and _ . : -")
            return
        kind, args = command.get("type"), command.get("args", {})
        if kind not in COMMAND_TYPES:
            self._refuse(given, f"type: one of {', '.join(COMMAND_TYPES)}")
            return
        if not isinstance(args, dict):
            self._refuse(given, "args: a JSON object")
            return
        problem = command_problem(kind, args)
        if problem is not None:
            self._refuse(given, problem)
            return
        with self._lock:
            self._count += 1
            command_id = f"ros2:{given or self._count}"
            if command_id in self._waiting or len(self._waiting) >= AT_MOST_WAITING:
                busy = True
            else:
                busy = False
                self._waiting[command_id] = self.clock.now()
        if busy:
            self._refuse(given, f"busy: {AT_MOST_WAITING} commands are waiting, or this id is")
            return
        assert self.blackboard is not None
        self.blackboard.stage_event(IOT_INBOX, {"id": command_id, "type": kind, "args": args})
        self._tell(command_id, "RECEIVED", None)

    def _refuse(self, given: Any, why: str) -> None:
        log.warning("ros2: a command was refused: %s", why)
        self._tell(f"ros2:{given}" if given else None, "REFUSED", {"error": why})

    def _tell(self, command_id: str | None, status: str, result: Any) -> None:
        """How a command stands, on the result topic, under the id its sender gave."""
        given = command_id.removeprefix("ros2:") if command_id else None
        message = {"id": given, "status": status, "result": result}
        self._publish(RESULT_TOPIC, STRING, {"data": json.dumps(message)}, self.clock.now())

    # -- helpers ---------------------------------------------------------------------------
    def _declare_token(self, key: str) -> Any:
        assert self._session is not None
        return self._session.liveliness().declare_token(key)

    def _next_entity(self) -> int:
        self._entities += 1
        return self._entities


def _first_line(error: BaseException) -> str:
    """Zenoh's message without the Rust source place it appends."""
    return str(error).splitlines()[0].split(" at /")[0]
