"""A validated tree: what the loader hands the scheduler, built into py_trees on demand.

A :class:`TreeDefinition` holds no py_trees objects: it can be built again and again (a
hot reload, a test harness, a benchmark), each time with the :class:`TreeContext` of the
robot that runs it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import py_trees

from engine.files.problems import Mark
from engine.nodes.context import TreeContext
from engine.nodes.spec import NodeType


@dataclass
class NodeDefinition:
    """One validated node: its type, display name, converted arguments and children."""

    type: NodeType
    name: str
    args: dict[str, Any]
    children: list[NodeDefinition]
    mark: Mark
    subtree: str | None = None
    """For the root of an included subtree: the file it came from, as written."""

    def walk(self) -> Iterator[NodeDefinition]:
        """This node and every node under it, depth-first."""
        yield self
        for child in self.children:
            yield from child.walk()


@dataclass
class TreeDefinition:
    """A validated tree file, ready to build as often as needed."""

    name: str
    rate_hz: float
    description: str
    root: NodeDefinition
    path: Path
    files: list[Path] = field(default_factory=list)
    declared_params: frozenset[str] = frozenset()
    """Parameter names this tree and its subtrees declare (what a profile may set)."""
    priority: int = 0
    """0..99 (100: the therapist's buttons): higher interrupts lower for the speaker, the
    face LEDs and the joints."""
    wait_for_turn_s: float = 0.0
    """How long an action waits for a resource another tree has (0: let it go at once)."""
    when_interrupted: str = "let_go"
    """A round a higher tree cut short: ``let_go`` (the events that started it are spent)
    or ``try_again`` (it starts again with them)."""
    wake_on: tuple[str, ...] = ()
    """Keys whose change ticks the tree at once; with them it rests between rounds."""
    interruptible: bool = True
    """Whether a person speaking over the robot stops this tree's sentences."""

    def build(self, ctx: TreeContext) -> py_trees.trees.BehaviourTree:
        """A fresh py_trees tree whose nodes use ``ctx``."""
        return py_trees.trees.BehaviourTree(_build(self.root, ctx))


def _build(node: NodeDefinition, ctx: TreeContext) -> py_trees.behaviour.Behaviour:
    children = [_build(child, ctx) for child in node.children]
    return node.type.build(node.name, SimpleNamespace(**node.args), children, ctx)
