"""What changed in the running trees since the last look, published as session events.

After each tick :class:`TreeNews` asks :class:`TreeWatch` which nodes of that tree changed
status or feedback message and publishes each change as a
:class:`~engine.session.events.NodeStatus`. Nodes are numbered depth-first, as ``vest
render`` numbers them (``n0`` is the root); a hot reload makes a new version of the tree
(a :class:`~engine.session.events.TreeStarted`), its nodes numbered afresh. Looking costs a
walk over the tree's nodes, no copy of the tree, and only when a reader wants statuses.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import py_trees

from engine.blackboard.catalogue import NOTHING, Carries
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_drawing import dot_source, label, plain_label, preorder
from engine.nodes.base import node_path
from engine.runtime.scheduler import RunningTree
from engine.session.events import NodeInfo, NodeStatus, TreeStarted
from engine.session.stream import SessionStream


@dataclass
class WatchedTree:
    """One version of a running tree and the last status and feedback seen of each node."""

    name: str
    version: int
    definition: TreeDefinition
    nodes: list[py_trees.behaviour.Behaviour]
    info: list[NodeInfo]
    last: list[tuple[str, str]] = field(default_factory=list)
    ticks: int = 0


StatusChange = tuple[int, str, str]
"""(node number, status name, feedback message)."""


class TreeWatch:
    """Remembers what each tree looked like, so only changes are told."""

    def __init__(self) -> None:
        self.trees: dict[str, WatchedTree] = {}

    def watch(self, tree: RunningTree) -> WatchedTree:
        """Start watching ``tree`` as it is now (a new version if it was reloaded)."""
        known = self.trees.get(tree.name)
        nodes = _preorder_nodes(tree.tree.root)
        definitions = list(preorder(tree.definition.root))
        catalogue = tree.context.blackboard.catalogue
        info = [
            NodeInfo(
                index,
                node_path(node),
                definition.type.name,
                label(definition),
                depth,
                " ".join(plain_label(definition, catalogue).split()),
            )
            for index, (node, (definition, depth)) in enumerate(
                zip(nodes, definitions, strict=True)
            )
        ]
        watched = WatchedTree(
            tree.name,
            1 if known is None else known.version + 1,
            tree.definition,
            nodes,
            info,
            [("", "")] * len(nodes),
        )
        self.trees[tree.name] = watched
        return watched

    def look(self, tree: RunningTree) -> tuple[WatchedTree, bool, list[StatusChange]]:
        """After ``tree`` ticked: (its watched version, whether that version is new, the
        nodes whose status or feedback changed since the last look)."""
        watched = self.trees.get(tree.name)
        new = watched is None or watched.definition is not tree.definition
        if watched is None or new:
            watched = self.watch(tree)
        watched.ticks += 1
        changes: list[StatusChange] = []
        for index, node in enumerate(watched.nodes):
            status = node.status.name
            # a node not ticked keeps py_trees' last message: it no longer says anything
            feedback = "" if status == "INVALID" else node.feedback_message or ""
            now = (status, feedback)
            if now != watched.last[index]:
                watched.last[index] = now
                changes.append((index, *now))
        return watched, new, changes


def _preorder_nodes(root: py_trees.behaviour.Behaviour) -> list[py_trees.behaviour.Behaviour]:
    nodes = [root]
    for child in root.children:
        nodes.extend(_preorder_nodes(child))
    return nodes


class TreeNews:
    """Publishes each tree version as it starts and each node's changes after a tick."""

    def __init__(self, stream: SessionStream) -> None:
        self.stream = stream
        self.watch = TreeWatch()

    def started(self, tree: RunningTree) -> None:
        """Publish ``tree`` as it is now (at the session's start)."""
        self._publish_tree(self.watch.watch(tree), self.stream.clock.now())

    def _publish_tree(self, watched: WatchedTree, t_s: float) -> None:
        definition = watched.definition
        self.stream.publish(
            TreeStarted(
                t_s,
                watched.name,
                watched.version,
                definition.path,
                tuple(definition.files or [definition.path]),
                definition.rate_hz,
                definition.priority,
                tuple(watched.info),
                dot_source(definition),
            )
        )

    def __call__(self, tree: RunningTree) -> None:
        """After ``tree`` ticked (a scheduler after-tick observer)."""
        if not self.stream.wants(NodeStatus.kind) and not self.stream.wants(TreeStarted.kind):
            return
        watched, new, changes = self.watch.look(tree)
        if new:  # hot-reloaded, or a button's action swapped in
            self._publish_tree(watched, self.stream.clock.now())
        at = tree.next_deadline_s  # the statuses hold from the tick's deadline
        for index, status, feedback in changes:
            carries = _carried_by(watched.nodes[index]) if feedback else NOTHING
            self.stream.publish(
                NodeStatus(
                    at, tree.name, watched.version, watched.ticks, index, status, feedback, carries
                )
            )


def _carried_by(node: py_trees.behaviour.Behaviour) -> Carries:
    """What of a person a node's feedback may quote: what it reads (a leaf says), else
    nothing (a composite's or decorator's message tells of its children)."""
    carries = getattr(node, "carries", None)
    return carries() if callable(carries) else NOTHING
