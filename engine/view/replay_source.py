"""A recording as the view's data: the same state a live page gets, at any moment."""

from __future__ import annotations

import json
from typing import Any

from engine.blackboard.catalogue import VARIABLES_PREFIX, default_catalogue
from engine.recording.replay import Recording
from engine.recording.told import told_events
from engine.view.hub import RECENT_HAPPENINGS, Change, happened

STEP_S = 0.01
"""Moments closer than this are one step of the replay (one tick's changes)."""


def _steps(moments: list[float]) -> list[float]:
    """The moments a replay steps through: the last of each cluster (its changes all in)."""
    steps: list[float] = []
    for at in moments:
        if steps and at - steps[-1] < STEP_S:
            steps[-1] = at
        else:
            steps.append(at)
    return steps


class ReplaySource:
    """Answers the page's questions from a recording (:class:`Recording`)."""

    def __init__(self, recording: Recording) -> None:
        self.recording = recording
        self._catalogue = default_catalogue()

    def info(self) -> dict[str, Any]:
        return {
            "mode": "replay",
            "file": self.recording.path.name,
            "duration": self.recording.duration_s,
            "moments": _steps(self.recording.moments()),
            "actions": [action.at_s for action in self.recording.actions()],
        }

    def snapshot(self, at_s: float) -> Change:
        """The state at ``at_s``, shaped as :meth:`ViewHub.snapshot` shapes it."""
        recording = self.recording
        statuses = recording.statuses_at(at_s)
        trees = []
        for tree in recording.trees_at(at_s):
            trees.append(
                {
                    "kind": "tree",
                    "at": tree.at_s,
                    "tree": tree.name,
                    "version": tree.version,
                    "rate_hz": tree.rate_hz,
                    "nodes": [vars(node) for node in tree.nodes],
                    "statuses": [
                        {
                            "kind": "status",
                            "at": state.since_s,
                            "tree": tree.name,
                            "version": tree.version,
                            "node": node.index,
                            "status": state.status,
                            "feedback": state.feedback,
                        }
                        for node in tree.nodes
                        if (state := statuses.get((tree.name, tree.version, node.index)))
                    ],
                }
            )
        keys = []
        for key, written in sorted(recording.blackboard_at(at_s).items()):
            spec = self._catalogue.lookup(key)
            keys.append(
                {
                    "kind": "key",
                    "at": written.since_s,
                    "key": key,
                    "value": json.dumps(written.value),
                    "event": spec is not None and spec.kind == "event",
                    "writer": "trees"
                    if key.startswith(VARIABLES_PREFIX)
                    else (spec.writer if spec else ""),
                }
            )
        told = [happened(event, 0.0) for event in told_events(recording, at_s)]
        lines = [line for line in told if line is not None]
        return {
            "now": at_s,
            "trees": trees,
            "keys": keys,
            "happened": lines[-RECENT_HAPPENINGS:],
            "stats": {"kind": "stats", "at": at_s, "trees": {}, "devices": {}},
        }

    def dot(self, tree: str, version: int) -> str | None:
        return self.recording.dot(tree, version)

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]:
        return self.recording.node_changes(tree, version, node)
