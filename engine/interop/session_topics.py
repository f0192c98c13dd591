"""The live session as topics: each session event as the topic, schema name and JSON
message that ``vest replay --to mcap`` writes for it, shared by Foxglove's live server and
the ROS 2 bridge so a layout made on one works on the others."""

from __future__ import annotations

from typing import Any

from engine.session.codec import encode
from engine.session.events import (
    ActionEnded,
    ActionStarted,
    KeyChanged,
    NodeStatus,
    SessionEvent,
    TreeStarted,
    WorldEvent,
)
from engine.session.json_values import json_value

NodePaths = dict[tuple[str, int, int], tuple[str, str]]
"""(tree, version, node index) -> (the node's path, its type), from each TreeStarted."""


def live_message(event: SessionEvent, paths: NodePaths) -> tuple[str, str, dict[str, Any]] | None:
    """(topic, schema, message) of a session event, as the MCAP export writes it (the
    events of no topic of their own on ``/vest/events``, their fields as
    :mod:`engine.session.codec` writes them); None for a tree's start."""
    if isinstance(event, NodeStatus):
        path, kind = paths.get((event.tree, event.version, event.node), ("", ""))
        message = {
            "tree": event.tree,
            "version": event.version,
            "tick": event.tick,
            "node": event.node,
            "path": path,
            "type": kind,
            "status": event.status,
            "feedback": event.feedback,
        }
        return f"/vest/trees/{event.tree}/status", "vest.NodeStatus", message
    if isinstance(event, KeyChanged):
        message = {"key": event.key, "value": json_value(event.value), "event": event.event}
        return "/vest/blackboard", "vest.KeyChange", message
    if isinstance(event, ActionStarted):
        message = {"tree": event.tree, "action": event.action, "args": json_value(event.args)}
        return "/vest/actions", "vest.Action", message | {"outcome": None, "why": None}
    if isinstance(event, ActionEnded):
        message = {"tree": event.tree, "action": event.action, "args": json_value(event.args)}
        ended = {"outcome": event.outcome, "why": event.why or None}
        return "/vest/actions/outcome", "vest.Action", message | ended
    if isinstance(event, WorldEvent):
        message = {"kind": event.scenario_event, "description": event.description}
        return "/vest/world", "vest.WorldEvent", message
    if isinstance(event, TreeStarted):
        return None  # its nodes name the statuses' paths
    data = encode(event)
    kind, tree = data.pop("kind"), str(data.pop("tree", ""))
    del data["t"]
    return "/vest/events", "vest.SessionEvent", {"kind": kind, "tree": tree, "data": data}
