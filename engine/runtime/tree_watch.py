"""What changed in the running trees since the last look: for recordings and the live view.

After each tick the scheduler's observers ask :class:`TreeWatch` which nodes of that tree
changed status or feedback message. Nodes are numbered depth-first, as ``vest render``
numbers them (``n0`` is the root); a hot reload makes a new version of the tree, its
nodes numbered afresh. Looking costs a walk over the tree's nodes, no copy of the tree.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import py_trees

from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_drawing import label, preorder
from engine.nodes.base import node_path
from engine.runtime.scheduler import RunningTree


@dataclass(frozen=True)
class NodeInfo:
    """One node of a tree version: its number, path, type, label (as drawn) and depth."""

    index: int
    path: str
    type: str
    label: str
    depth: int


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
        info = [
            NodeInfo(index, node_path(node), definition.type.name, label(definition), depth)
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
