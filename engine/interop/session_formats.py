"""A recorded session in other tools' formats (``vest replay FILE --to mcap|btlog``).

- **btlog**: BehaviorTree.CPP's FileLogger2 file, which Groot2 replays: the magic
  ``BTCPP4-FileLogger2``, protocol byte 1, the tree's XML (int32 little-endian length; each
  node with its ``_uid``), the first timestamp (int64, microseconds since the epoch), then
  one 9-byte record per status change: 6 bytes of microseconds since the first timestamp,
  the node's uid (uint16), its status (uint8: 0 idle, 1 running, 2 success, 3 failure).
  One tree a file (Groot2 shows one); uids count from 1 in depth-first order, a SubTree
  node before the root of its subtree, as BehaviorTree.CPP numbers them.
- **MCAP** with JSON-schema channels, which Foxglove and Lichtblick open: ``/vest/trees/
  <tree>/status`` (a node's status and feedback), ``/vest/blackboard`` (each change),
  ``/vest/actions`` (each action, and ``/vest/actions/outcome`` how it ended),
  ``/vest/world`` (what the scenario did), ``/vest/events`` (turns, safety, presses...).
  Log times are the session's, in nanoseconds since the epoch.
"""

from __future__ import annotations

import json
import math
import struct
from collections.abc import Iterator, Mapping
from typing import Any, BinaryIO

from mcap.writer import Writer

from engine.interop.btcpp_export import BTCPP_BUILTINS, xml_safe
from engine.interop.session_topics import live_message
from engine.recording.replay import RecordedTree, Recording
from engine.recording.told import every_event
from engine.session.codec import LATEST_S
from engine.session.events import NodeInfo
from engine.session.json_values import json_value

MAGIC = b"BTCPP4-FileLogger2"
PROTOCOL = 1
STATUS_CODES = {"INVALID": 0, "IDLE": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3}


def _epoch_s(recording: Recording) -> float:
    """When the session started, seconds since the epoch (0 when the file cannot say)."""
    try:
        started = float(recording.meta.get("started", "0"))
    except ValueError:
        return 0.0
    return started if math.isfinite(started) and 0 <= started < 1e11 else 0.0


# -- btlog ----------------------------------------------------------------------------------
def btlog_tree_xml(tree: RecordedTree, kinds: Mapping[str, str]) -> tuple[str, dict[int, int]]:
    """The recorded tree as BehaviorTree.CPP XML with ``_uid`` on every node, and our node
    index -> its uid. Built from the recorded nodes (their type, label and depth): the
    tree as it ran, whatever its files say now. ``kinds``: our node type -> Action,
    Condition, Decorator or Control, for the TreeNodesModel Groot2 draws them by."""
    lines: list[str] = []
    uids: dict[int, int] = {}
    stack: list[tuple[int, str]] = []  # (depth, closing tag) of open elements
    nodes = list(tree.nodes)
    for position, node in enumerate(nodes):
        while stack and stack[-1][0] >= node.depth:
            depth, tag = stack.pop()
            lines.append(f"{'  ' * (depth + 2)}</{tag}>")
        uid = len(uids) + 1
        uids[node.index] = uid
        tag = _tag(node)
        following = nodes[position + 1] if position + 1 < len(nodes) else None
        has_children = following is not None and following.depth == node.depth + 1
        attributes = f' name="{_escape(node.label)}" _uid="{uid}"'
        indent = "  " * (node.depth + 2)
        if has_children:
            lines.append(f"{indent}<{tag}{attributes}>")
            stack.append((node.depth, tag))
        else:
            lines.append(f"{indent}<{tag}{attributes}/>")
    while stack:
        depth, tag = stack.pop()
        lines.append(f"{'  ' * (depth + 2)}</{tag}>")
    body = "\n".join(lines)
    xml = (
        f'<?xml version="1.0" encoding="UTF-8"?>\n<root BTCPP_format="4" '
        f'main_tree_to_execute="{_escape(tree.name)}">\n'
        f'  <BehaviorTree ID="{_escape(tree.name)}" _fullpath="">\n{body}\n  </BehaviorTree>\n'
        f"  <TreeNodesModel>\n{_model(tree, kinds)}  </TreeNodesModel>\n</root>\n"
    )
    return xml, uids


def _model(tree: RecordedTree, kinds: Mapping[str, str]) -> str:
    ours = {_tag(node): node.type for node in tree.nodes if _tag(node) not in BTCPP_BUILTINS}
    return "".join(
        f'    <{kinds.get(kind, "Action")} ID="{_escape(tag)}"/>\n'
        for tag, kind in sorted(ours.items())
    )


def _tag(node: NodeInfo) -> str:
    """The element a recorded node is written as, as ``vest export`` writes it: its
    settings read from its label (``Selector memory=True`` is a ``Fallback``)."""
    settings = dict(part.split("=", 1) for part in node.label.split() if "=" in part)
    kind = node.type
    if kind == "Sequence":
        return "ReactiveSequence" if settings.get("memory") == "False" else "Sequence"
    if kind == "Selector":
        return "Fallback" if settings.get("memory") == "True" else "ReactiveFallback"
    if kind == "Parallel":
        if settings.get("synchronise") == "False":
            return "VestParallel"
        return "Parallel" if settings.get("succeed_when") == "one" else "ParallelAll"
    if kind == "Retry":
        return "RetryUntilSuccessful"
    if kind == "OneShot" and settings.get("after") == "completion":
        return "RunOnce"
    return kind


def _escape(text: str) -> str:
    text = xml_safe(text)
    return (
        text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")
    )


def write_btlog(
    recording: Recording, tree_name: str, kinds: Mapping[str, str], out: BinaryIO
) -> int:
    """The session of ``tree_name`` (its first version) as a FileLogger2 file into
    ``out``; returns how many status changes were written."""
    tree = next(t for t in recording.trees if t.name == tree_name)
    xml, uids = btlog_tree_xml(tree, kinds)
    data = xml.encode("utf-8")
    first_us = round(_epoch_s(recording) * 1e6)
    out.write(MAGIC + bytes([PROTOCOL]) + struct.pack("<i", len(data)) + data)
    out.write(struct.pack("<q", first_us))
    written = 0
    for row in recording.table("statuses"):
        if row["tree"] != tree.name or row["version"] != tree.version:
            continue
        uid = uids.get(row["node"])
        code = STATUS_CODES.get(str(row["status"]))
        if uid is None or code is None:
            continue
        since_us = round(float(row["at_s"]) * 1e6)
        if not 0 <= since_us < 2**48:  # 6 bytes: a damaged time
            raise ValueError(f"a status at {row['at_s']!r} s")
        out.write(since_us.to_bytes(6, "little") + struct.pack("<HB", uid, code))
        written += 1
    return written


# -- MCAP -----------------------------------------------------------------------------------
SCHEMAS: dict[str, dict[str, Any]] = {
    "vest.NodeStatus": {
        "type": "object",
        "properties": {
            "tree": {"type": "string"},
            "version": {"type": "integer"},
            "tick": {"type": "integer"},
            "node": {"type": "integer", "description": "depth-first, 0 is the root"},
            "path": {"type": "string"},
            "type": {"type": "string"},
            "status": {"type": "string", "enum": ["INVALID", "RUNNING", "SUCCESS", "FAILURE"]},
            "feedback": {"type": "string"},
        },
    },
    "vest.KeyChange": {
        "type": "object",
        "properties": {"key": {"type": "string"}, "value": {}, "event": {"type": "boolean"}},
    },
    "vest.Action": {
        "type": "object",
        "properties": {
            "tree": {"type": "string"},
            "action": {"type": "string"},
            "args": {"type": "object"},
            "outcome": {"type": ["string", "null"], "enum": ["done", "failed", "cut", None]},
            "why": {"type": ["string", "null"]},
        },
    },
    "vest.WorldEvent": {
        "type": "object",
        "properties": {"kind": {"type": "string"}, "description": {"type": "string"}},
    },
    "vest.SessionEvent": {
        "type": "object",
        "properties": {"kind": {"type": "string"}, "tree": {"type": "string"}, "data": {}},
    },
}


def _messages(recording: Recording) -> Iterator[tuple[str, str, float, dict[str, Any]]]:
    """(topic, schema, at_s, message) for everything the session kept, as the live
    Foxglove server and the ROS 2 bridge send it (:func:`live_message`)."""
    paths = {
        (tree.name, tree.version, node.index): (node.path, node.type)
        for tree in recording.trees
        for node in tree.nodes
    }
    for event in every_event(recording):
        found = live_message(event, paths)
        if found is not None:
            yield found[0], found[1], event.t_s, found[2]


def write_mcap(recording: Recording, out: BinaryIO) -> dict[str, int]:
    """The session as MCAP with JSON-schema channels into ``out``; returns how many
    messages each topic got."""
    writer = Writer(out)
    writer.start(profile="", library="vest")
    schema_ids = {
        name: writer.register_schema(name, "jsonschema", json.dumps(schema).encode())
        for name, schema in SCHEMAS.items()
    }
    channels: dict[str, int] = {}
    counts: dict[str, int] = {}
    start_ns = round(_epoch_s(recording) * 1e9)
    messages = sorted(_messages(recording), key=lambda m: m[2])  # time order, stable
    for topic, schema, at_s, message in messages:
        if not (math.isfinite(float(at_s)) and 0 <= float(at_s) < LATEST_S):
            raise ValueError(f"{topic} at {at_s!r} s")
        if topic not in channels:
            channels[topic] = writer.register_channel(topic, "json", schema_ids[schema])
        at_ns = start_ns + round(float(at_s) * 1e9)
        data = json.dumps(json_value(message), allow_nan=False).encode()  # NaN: null
        writer.add_message(channels[topic], at_ns, data, at_ns, counts.get(topic, 0))
        counts[topic] = counts.get(topic, 0) + 1
    writer.finish()  # type: ignore[no-untyped-call]
    return counts


def write_session(
    recording: Recording, kind: str, out: BinaryIO, tree: str | None, kinds: Mapping[str, str]
) -> str:
    """Writes the session as ``kind`` (mcap or btlog) into ``out``; what it wrote, in
    words. ``kinds``: our node types' kinds, as :func:`btlog_tree_xml` takes them."""
    if kind == "mcap":
        counts = write_mcap(recording, out)
        return f"{sum(counts.values())} messages on {len(counts)} topics (MCAP)"
    assert tree is not None
    written = write_btlog(recording, tree, kinds, out)
    return f"{tree}, {written} status changes (BehaviorTree.CPP FileLogger2)"
