"""How a ROS 2 graph running ``rmw_zenoh`` carries a topic, written without ROS: the
names, key expressions, liveliness tokens, attachments and CDR payloads that
``rmw_zenoh_cpp`` (ROS 2 Jazzy and later) uses, so a ROS 2 node sees vest as one of its own.

- A message travels on the key ``<domain>/<topic without its leading />/<type>/<hash>``,
  e.g. ``0/vest/actions/std_msgs::msg::dds_::String_/RIHS01_df66...``: the type as DDS
  names it, the hash its RIHS01 type hash (REP 2011), both computed by ``rosbags``.
- Its payload is the message in CDR (little-endian, with the 4-byte encapsulation
  header); its attachment the publisher's sequence number and the source time (int64,
  nanoseconds since the epoch) and the publisher's 16-byte gid, in Zenoh's own
  serialization (``zenoh.ext``).
- Each node, publisher and subscription declares a liveliness token under ``@ros2_lv``
  (node ``NN``, publisher ``MP``, subscription ``MS``), which is how ``ros2 node list`` and
  ``ros2 topic list`` find it; a name's slashes are written ``%``, an empty one is ``%``.

Types are ROS 2 Jazzy's (``std_msgs``, ``builtin_interfaces``), and Nav2's
``BehaviorTreeLog`` / ``BehaviorTreeStatusChange`` as Nav2's main branch defines them
(with ``uid``): a Nav2 older than that has another type hash, and its tools will not match.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from typing import Any

import zenoh
import zenoh.ext
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

NAV2_STATUS_CHANGE = """\
builtin_interfaces/Time timestamp
string node_name
uint16 uid
string previous_status
string current_status
"""
NAV2_LOG = """\
builtin_interfaces/Time timestamp
nav2_msgs/msg/BehaviorTreeStatusChange[] event_log
"""
LIVELINESS_PREFIX = "@ros2_lv"
RELIABLE_DEPTH_10 = "::,10:,:,:,,"
"""rmw_zenoh's QoS in a token: reliable, volatile, keep last (its defaults, written empty),
depth 10 (written: rmw_zenoh's default depth is 42), no deadline, lifespan or lease."""
_NAME_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def typestore() -> Typestore:
    """ROS 2 Jazzy's types and Nav2's behavior tree log."""
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(
        get_types_from_msg(NAV2_STATUS_CHANGE, "nav2_msgs/msg/BehaviorTreeStatusChange")
        | get_types_from_msg(NAV2_LOG, "nav2_msgs/msg/BehaviorTreeLog")
    )
    return store


def ros_name(path: str) -> str:
    """``path`` as a valid ROS 2 name: each part a letter or ``_`` then letters, digits,
    ``_`` (``/devices/0x5A/ok`` -> ``/devices/_0x5A/ok``; ``left-arm`` -> ``left_arm``)."""
    parts = []
    for part in path.strip("/").split("/"):
        cleaned = re.sub(r"[^A-Za-z0-9_]", "_", part) or "_"
        parts.append(cleaned if _NAME_TOKEN.fullmatch(cleaned) else "_" + cleaned)
    return "/" + "/".join(parts)


def dds_type(typename: str) -> str:
    """``std_msgs/msg/String`` -> ``std_msgs::msg::dds_::String_``."""
    package, kind, name = typename.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def mangled(name: str) -> str:
    """A name as a liveliness token carries it: slashes as ``%``, empty as ``%``."""
    return name.replace("/", "%") or "%"


@dataclass(frozen=True)
class Endpoint:
    """One topic of one ROS 2 type, as rmw_zenoh names it on the wire."""

    topic: str
    typename: str
    type_hash: str

    def key(self, domain: int) -> str:
        return f"{domain}/{self.topic.lstrip('/')}/{dds_type(self.typename)}/{self.type_hash}"

    def token(self, domain: int, zid: str, node: NodeName, entity: int, kind: str) -> str:
        """The liveliness token of a publisher (``MP``) or subscription (``MS``)."""
        typed = f"{mangled(self.topic)}/{dds_type(self.typename)}/{self.type_hash}"
        return f"{node.token(domain, zid, kind, entity)}/{typed}/{RELIABLE_DEPTH_10}"


@dataclass(frozen=True)
class NodeName:
    """A ROS 2 node: ``name`` in ``namespace`` ('' for the root)."""

    name: str
    namespace: str = ""

    def token(self, domain: int, zid: str, kind: str = "NN", entity: int = 0) -> str:
        where = f"{mangled('')}/{mangled(self.namespace)}/{self.name}"  # no enclave
        return f"{LIVELINESS_PREFIX}/{domain}/{zid}/0/{entity}/{kind}/{where}"


class Wire:
    """Encodes and decodes the messages of one node's endpoints."""

    def __init__(self, store: Typestore | None = None) -> None:
        self.store = store or typestore()

    def endpoint(self, topic: str, typename: str) -> Endpoint:
        return Endpoint(topic, typename, self.store.hash_rihs01(typename))

    def encode(self, typename: str, fields: dict[str, Any]) -> bytes:
        """A message of ``typename`` from its fields (nested messages as dicts)."""
        return bytes(self.store.serialize_cdr(self._message(typename, fields), typename))

    def decode(self, typename: str, payload: bytes) -> Any:
        """The message in ``payload`` (ValueError when it is not one of ``typename``)."""
        try:
            return self.store.deserialize_cdr(payload, typename)
        except Exception as error:  # rosbags raises several kinds on a short or bad buffer
            raise ValueError(f"not a {typename}: {error}") from None

    def _message(self, typename: str, fields: dict[str, Any]) -> Any:
        kind = self.store.types[typename]
        built: dict[str, Any] = {}
        for name, (field_kind, detail) in self.store.fielddefs[typename][1]:
            value = fields[name]
            if field_kind == Nodetype.NAME:  # a nested message
                value = self._message(str(detail), value)
            elif field_kind == Nodetype.SEQUENCE:
                item_kind: Any = detail[0]
                if item_kind[0] == Nodetype.NAME:  # of messages
                    value = [self._message(str(item_kind[1]), item) for item in value]
            built[name] = value
        return kind(**built)


def attachment(sequence: int, source_ns: int, gid: bytes) -> bytes:
    """What rmw_zenoh attaches to each message: its sequence number, the source time
    (nanoseconds since the epoch) and the publisher's 16-byte gid."""
    serialized = zenoh.ext.z_serialize((zenoh.ext.Int64(sequence), zenoh.ext.Int64(source_ns), gid))
    return bytes(serialized.to_bytes())


def publisher_gid(zid: str, entity: int) -> bytes:
    """A publisher's 16-byte gid, unique in the graph (from its session and number)."""
    return hashlib.sha256(f"{zid}/{entity}".encode()).digest()[:16]


def ros_time(seconds: float) -> dict[str, int]:
    """``builtin_interfaces/Time`` of ``seconds`` since the epoch."""
    nanoseconds = max(0, round(seconds * 1e9))
    return {"sec": nanoseconds // 1_000_000_000, "nanosec": nanoseconds % 1_000_000_000}


def session_config(
    connect: str | None, config_file: str | None, *, listen: str = "tcp/127.0.0.1:0"
) -> zenoh.Config:
    """A peer session that connects to the Zenoh router at ``connect`` (as rmw_zenoh's
    nodes do: ``tcp/127.0.0.1:7447`` by default; None: to nobody) and listens on ``listen``
    for its peers (loopback, any port); ``config_file`` (rmw_zenoh's
    ``ZENOH_SESSION_CONFIG_URI``) replaces all of this. A graph's stand-in (the tests', the
    bench's) connects to nobody and listens where the robot connects. Raises zenoh.ZError
    for an endpoint or file it cannot use."""
    if config_file:
        return zenoh.Config.from_file(config_file)
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")  # the router tells of peers
    config.insert_json5("connect/endpoints", json.dumps([connect] if connect else []))
    config.insert_json5("listen/endpoints", json.dumps([listen]))
    return config
