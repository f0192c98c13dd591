"""A recording as the view's data: the same state a live page gets, at any moment."""

from __future__ import annotations

import json
from typing import Any

from engine.blackboard.catalogue import VARIABLES_PREFIX, default_catalogue
from engine.clock import VirtualClock
from engine.recording.replay import Recording
from engine.recording.told import told_events
from engine.session.events import KeyChanged, NodeStatus, TreeStarted
from engine.view.hub import Change, ViewHub

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
        """The state at ``at_s``: the recording's state then, told to a :class:`ViewHub`
        as the live run told it, so a replay's page is shaped as the live one."""
        recording = self.recording
        hub = ViewHub(VirtualClock(at_s))
        hub.begin(0.0, [])
        statuses = recording.statuses_at(at_s)
        for tree in recording.trees_at(at_s):
            hub.on_event(
                TreeStarted(
                    tree.at_s,
                    tree.name,
                    tree.version,
                    tree.file,
                    (),
                    tree.rate_hz,
                    0,
                    tree.nodes,
                    "",
                )
            )
            for node in tree.nodes:
                state = statuses.get((tree.name, tree.version, node.index))
                if state is not None:
                    hub.on_event(
                        NodeStatus(
                            state.since_s,
                            tree.name,
                            tree.version,
                            0,
                            node.index,
                            state.status,
                            state.feedback,
                        )
                    )
        for key, written in sorted(recording.blackboard_at(at_s).items()):
            spec = self._catalogue.lookup(key)
            event = spec is not None and spec.kind == "event"
            writer = "trees" if key.startswith(VARIABLES_PREFIX) else (spec.writer if spec else "")
            text = json.dumps(written.value)
            hub.on_event(KeyChanged(written.since_s, key, written.value, text, event, writer))
        for told in told_events(recording, at_s):
            hub.on_event(told)
        return hub.snapshot()

    def dot(self, tree: str, version: int) -> str | None:
        return self.recording.dot(tree, version)

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]:
        return self.recording.node_changes(tree, version, node)
