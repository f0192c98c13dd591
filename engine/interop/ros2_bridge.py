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

It reads the consent gate's ``sent`` exit (:mod:`engine.privacy.consent_gate`), as the
cloud's telemetry does: without ``cloud_telemetry`` only the robot's own account leaves
(its trees' statuses, which actions it took and how they ended, its devices; an action's
arguments and a turn's words only where they were made of nothing of the person: where it
looked, a Say that fills in a reading or what was heard, are withheld); never a reading,
a heard word, the world's events. With it, what a recording of the person keeps.

Commands, only when asked for (``--ros2-commands``: a ROS 2 graph has no accounts, so
anyone on it may then command the robot), go the cloud's way
(:mod:`engine.interop.ros2_commands`): never raw actuator access.

A session reader: the scheduler's thread only hands each event over
(:class:`~engine.session.handoff.Handoff`); a thread beside it publishes.
"""

from __future__ import annotations

import json
import logging
import threading
from typing import Any

import zenoh

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import (
    DEVICES_PREFIX,
    SENSORS_PREFIX,
    SPEECH_PREFIX,
    VISION_PREFIX,
    KeyCatalogue,
)
from engine.blackboard.events import EventLog
from engine.clock import Clock
from engine.errors import ConfigError
from engine.interop.ros2_commands import GraphCommands
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
from engine.periodic import Periodic
from engine.privacy.consent_gate import ConsentGate
from engine.session.events import (
    ActionStarted,
    KeyChanged,
    NodeStatus,
    SessionEvent,
    TreeStarted,
)
from engine.session.handoff import Handoff
from engine.session.json_values import json_value

log = logging.getLogger(__name__)
CAPACITY = 50_000
"""Events the queue holds before it drops (seconds of the busiest session)."""
PUBLISHED_KEYS = (SENSORS_PREFIX, VISION_PREFIX, SPEECH_PREFIX, DEVICES_PREFIX)
COMMAND_TOPIC, RESULT_TOPIC = "/vest/command", "/vest/command/result"
STRING, BOOL = "std_msgs/msg/String", "std_msgs/msg/Bool"
FLOAT, INTEGER = "std_msgs/msg/Float64", "std_msgs/msg/Int64"
TREE_LOG = "nav2_msgs/msg/BehaviorTreeLog"
CLOSING_AT_MOST_S = 2.0
"""How long stopping waits for Zenoh to close (a router that took the connection and
never answers would hold it for its 10 s handshake)."""
BT_STATUS = {"INVALID": "IDLE", "RUNNING": "RUNNING", "SUCCESS": "SUCCESS", "FAILURE": "FAILURE"}


class Ros2Bridge:
    """Publishes the session on a ROS 2 graph, and takes commands from it when asked."""

    def __init__(
        self,
        plan: Ros2Plan,
        clock: Clock,
        epoch_offset_s: float,
        gate: ConsentGate,
        catalogue: KeyCatalogue,
    ) -> None:
        """``plan``: where the graph is and whether commands are taken; ``epoch_offset_s``
        turns the clock's seconds into seconds since the epoch (ROS time); ``gate``: the
        consent gate's exit off the robot (a command's result passes it too)."""
        self.plan, self.clock, self.epoch_offset_s = plan, clock, epoch_offset_s
        self.catalogue = catalogue
        self.node = NodeName("vest", plan.prefix)
        self.wire = Wire()
        self._session: zenoh.Session | None = None
        self._zid = ""
        self._tokens: list[Any] = []  # liveliness tokens, kept while the bridge runs
        self._publishers: dict[tuple[str, str], tuple[Endpoint, Any, bytes]] = {}
        self._sequence: dict[tuple[str, str], int] = {}
        self._paths: NodePaths = {}
        self._statuses: dict[tuple[str, int, int], str] = {}
        self._lock = threading.Lock()  # the publishers: two threads publish
        self._entities = 0  # the node's publishers and subscriptions, numbered
        self._handoff = Handoff("ros2", self._send, capacity=CAPACITY)
        self.commands = GraphCommands(clock, self._tell, gate=gate)
        self._sweep = Periodic(clock, 1.0, self.commands.sweep, name="ros2-commands")

    # -- lifecycle -----------------------------------------------------------------------
    def start(self, blackboard: Blackboard) -> None:
        """Joins the graph (ConfigError for a router address or file Zenoh cannot use; a
        router not up yet is tried again by Zenoh meanwhile) and starts publishing."""
        self.commands.blackboard = blackboard
        try:
            self._session = zenoh.open(session_config(self.plan.router, self.plan.config_file))
        except zenoh.ZError as error:
            why = _first_line(error)
            raise ConfigError(f"--ros2 {self.where}: Zenoh cannot use it ({why})") from None
        self._zid = str(self._session.zid())
        self._tokens.append(self._declare_token(self.node.token(self.plan.domain, self._zid)))
        if self.plan.commands:
            command = self.wire.endpoint(self.plan.prefix + COMMAND_TOPIC, STRING)
            entity = self._next_entity()
            self._publisher(RESULT_TOPIC, STRING)  # declared now: a sender can wait for it
            self._tokens.append(
                self._session.declare_subscriber(command.key(self.plan.domain), self._command_in)
            )  # then its token: a node that sees the token finds the subscriber there
            token = command.token(self.plan.domain, self._zid, self.node, entity, "MS")
            self._tokens.append(self._declare_token(token))
            self._sweep.start()
        self._handoff.start()

    @property
    def where(self) -> str:
        return self.plan.config_file or self.plan.router

    def on_event(self, event: SessionEvent) -> None:
        """The scheduler's thread: queued, never waited for."""
        self._handoff.put(event)

    def stop(self) -> None:
        """Publishes what is queued, tells commands still waiting LOST, leaves the graph
        (its tokens go: the graph sees the node leave), waiting for Zenoh at most
        CLOSING_AT_MOST_S."""
        self._handoff.close()
        if self._sweep.running:
            self._sweep.stop()
        if self._session is not None:
            self.commands.stopped()
            closing = threading.Thread(target=self._session.close, name="ros2-close", daemon=True)
            closing.start()
            closing.join(CLOSING_AT_MOST_S)
            self._session = None
        if self._handoff.dropped:
            log.warning("ros2: %d events were dropped", self._handoff.dropped)

    # -- publishing (the bridge's thread) --------------------------------------------------
    def _send(self, events: list[SessionEvent]) -> bool:
        logs: dict[str, list[dict[str, Any]]] = {}
        for event in events:  # what the consent gate let leave the robot
            if isinstance(event, ActionStarted) and event.action == "report":
                self.commands.reported(event)
            if isinstance(event, TreeStarted):
                for node in event.nodes:
                    self._paths[(event.tree, event.version, node.index)] = (node.path, node.type)
            elif isinstance(event, NodeStatus):
                logs.setdefault(event.tree, []).append(self._status_change(event))
            elif isinstance(event, KeyChanged):
                if event.key.startswith(PUBLISHED_KEYS):
                    self._key(event)
            else:
                found = live_message(event, self._paths)
                if found is not None:
                    topic, _, message = found
                    self._publish(topic, STRING, {"data": json.dumps(message)}, event.t_s)
        now_s = self.clock.now()
        for tree, changes in logs.items():
            stamp = ros_time(now_s + self.epoch_offset_s)
            topic = ros_name(f"/vest/trees/{tree}/log")
            self._publish(topic, TREE_LOG, {"timestamp": stamp, "event_log": changes}, now_s)
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
        elif declared is int and isinstance(value, int) and not isinstance(value, bool):
            self._publish(topic, INTEGER, {"data": max(-(2**63), min(value, 2**63 - 1))}, event.t_s)
        elif declared not in (bool, float, int):
            text = value if isinstance(value, str) else json.dumps(json_value(value))
            self._publish(topic, STRING, {"data": text}, event.t_s)

    def _publish(self, topic: str, typename: str, fields: dict[str, Any], at_s: float) -> None:
        try:
            payload = self.wire.encode(typename, fields)
        except Exception as error:  # a value the type cannot carry: the rest goes on
            log.warning("ros2: %s not sent (%s)", topic, error)
            return
        with self._lock:
            endpoint, publisher, gid = self._publisher(topic, typename)
            typed = (topic, typename)
            sequence = self._sequence[typed] = self._sequence.get(typed, 0) + 1
        source_ns = max(0, round((at_s + self.epoch_offset_s) * 1e9))
        try:
            publisher.put(payload, attachment=attachment(sequence, source_ns, gid))
        except zenoh.ZError as error:
            log.warning("ros2: %s not sent (%s)", endpoint.topic, _first_line(error))

    def _publisher(self, topic: str, typename: str) -> tuple[Endpoint, Any, bytes]:
        """The publisher of ``topic`` (declared, with its token, on first use; the lock
        held where another thread may publish too)."""
        found = self._publishers.get((topic, typename))
        if found is not None:
            return found
        assert self._session is not None
        endpoint = self.wire.endpoint(self.plan.prefix + topic, typename)
        entity = self._next_entity()
        domain = self.plan.domain
        publisher = self._session.declare_publisher(endpoint.key(domain))
        token = endpoint.token(domain, self._zid, self.node, entity, "MP")
        self._tokens.append(self._declare_token(token))
        gid = publisher_gid(self._zid, entity)
        found = self._publishers[(topic, typename)] = (endpoint, publisher, gid)
        return found

    # -- commands (Zenoh's thread) ---------------------------------------------------------
    def _command_in(self, sample: zenoh.Sample) -> None:
        try:
            text = self.wire.decode(STRING, bytes(sample.payload.to_bytes())).data
        except ValueError as error:
            self.commands.refuse(None, f"not a std_msgs/msg/String ({error})")
            return
        self.commands.received(str(text))

    def _tell(self, given: str | None, status: str, result: Any) -> None:
        """How a command stands, on the result topic, under the id its sender gave."""
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
