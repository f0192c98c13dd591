"""One tree, two engines: ours (built from YAML by our loader) and BehaviorTree.CPP v4
(built from its XML by ``behaviortreepy``), with the same scripted leaves.

A tree is written once as :class:`Node` values; each node names our type with its YAML
arguments and the BehaviorTree.CPP type with its XML attributes. A leaf is a name: in both
engines it answers, tick after tick of its own, the statuses of its script (``"RRS"``:
RUNNING, RUNNING, SUCCESS, then SUCCESS again), and notes that it was ticked or halted
(stopped while RUNNING). Each engine's run is a list of :class:`Step`, one per tree tick:
the root's status, the leaves ticked and the leaves halted in that tick, in order.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar
from xml.sax.saxutils import quoteattr

import behaviortreepy as btcpp
import yaml
from py_trees.common import Status

from engine.nodes import Leaf
from engine.nodes.registry import NodeRegistry, builtin_registry
from engine.testing import TreeHarness

LETTERS = {"S": "SUCCESS", "F": "FAILURE", "R": "RUNNING"}


@dataclass(frozen=True)
class Node:
    """A composite or decorator, as each engine spells it, and its children."""

    ours: str
    theirs: str
    children: tuple[Node | str, ...]
    args: Mapping[str, Any] = field(default_factory=dict)
    """Our YAML arguments."""
    attrs: Mapping[str, str] = field(default_factory=dict)
    """BehaviorTree.CPP's XML attributes."""


@dataclass(frozen=True)
class Step:
    """One tree tick: the root's status, and the leaves ticked and halted, in order."""

    status: str
    ticked: str = ""
    halted: str = ""

    def __repr__(self) -> str:
        return f"Step({self.status!r}, ticked={self.ticked!r}, halted={self.halted!r})"


class Book:
    """The leaves' scripts and what happened to them during the current tick."""

    def __init__(self, scripts: Mapping[str, str]) -> None:
        for name, script in scripts.items():
            if not script or set(script) - set(LETTERS):
                raise ValueError(f"leaf {name}: a script is letters S, F, R; got {script!r}")
        self.scripts = dict(scripts)
        self.answered: dict[str, int] = dict.fromkeys(scripts, 0)
        self.ticked: list[str] = []
        self.halted: list[str] = []

    def answer(self, leaf: str) -> str:
        """The status ``leaf`` answers to its next tick."""
        script = self.scripts[leaf]
        letter = script[min(self.answered[leaf], len(script) - 1)]
        self.answered[leaf] += 1
        self.ticked.append(leaf)
        return LETTERS[letter]

    def halt(self, leaf: str) -> None:
        self.halted.append(leaf)

    def step(self, status: str) -> Step:
        step = Step(status, " ".join(self.ticked), " ".join(self.halted))
        self.ticked.clear()
        self.halted.clear()
        return step


# -- ours ---------------------------------------------------------------------------------
class Scripted(Leaf):
    """A leaf that answers its script, one status per tick of its own."""

    params: ClassVar = ()

    def __init__(self, name: str, args: Any, ctx: Any, *, book: Book) -> None:
        super().__init__(name, args, ctx)
        self.book = book

    def update(self) -> Status:
        return Status[self.book.answer(self.name)]

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.status == Status.RUNNING:
            self.book.halt(self.name)


def our_yaml(node: Node | str, registry: NodeRegistry) -> dict[str, Any]:
    """The node as our YAML (a mapping of one node type)."""
    if isinstance(node, str):
        return {"Scripted": {"name": node}}
    children = [our_yaml(child, registry) for child in node.children]
    node_type = registry.get(node.ours)
    if node_type is not None and node_type.kind == "decorator":
        [child] = children
        return {node.ours: {**node.args, "child": child}}
    return {node.ours: {**node.args, "children": children}}


class Ours:
    """The tree built by our loader, ticked by the test harness on a virtual clock."""

    def __init__(self, tree: Node, scripts: Mapping[str, str], folder: Path, rate_hz: int) -> None:
        self.book = Book(scripts)
        registry = builtin_registry()
        registry.add(Scripted, book=self.book)
        path = folder / "compared.yaml"
        text = yaml.safe_dump(
            {"rate_hz": rate_hz, "root": our_yaml(tree, registry)}, sort_keys=False
        )
        path.write_text(text, encoding="utf-8")
        self.robot = TreeHarness.from_file(path, registry=registry)

    def tick(self) -> Step:
        return self.book.step(self.robot.tick().name)


def ours(
    tree: Node, scripts: Mapping[str, str], ticks: int, folder: Path, *, rate_hz: int = 10
) -> list[Step]:
    engine = Ours(tree, scripts, folder, rate_hz)
    return [engine.tick() for _ in range(ticks)]


# -- BehaviorTree.CPP ---------------------------------------------------------------------
def their_xml(node: Node | str) -> str:
    """The node as BehaviorTree.CPP v4 XML."""
    if isinstance(node, str):
        return f"<Scripted name={quoteattr(node)}/>"
    attrs = "".join(f" {key}={quoteattr(value)}" for key, value in node.attrs.items())
    inner = "".join(their_xml(child) for child in node.children)
    return f"<{node.theirs}{attrs}>{inner}</{node.theirs}>"


class Theirs:
    """The tree built by BehaviorTree.CPP's factory, ticked exactly once per step."""

    def __init__(self, tree: Node, scripts: Mapping[str, str]) -> None:
        self.book = Book(scripts)
        self.a_halt = threading.Event()
        book = self.book

        def tick(node: Any) -> Any:
            return getattr(btcpp.NodeStatus, book.answer(node.name()))

        def halted(node: Any) -> None:
            book.halt(node.name())
            self.a_halt.set()  # Timeout's timer thread halts between ticks

        factory = btcpp.BehaviorTreeFactory()
        factory.register_simple_stateful_action("Scripted", tick, tick, halted)
        xml = (
            '<root BTCPP_format="4" main_tree_to_execute="Main">'
            f'<BehaviorTree ID="Main">{their_xml(tree)}</BehaviorTree></root>'
        )
        self.tree = factory.create_tree_from_text(xml)

    def wait_for_a_halt(self) -> list[str]:
        """Wait until a leaf is halted from another thread (Timeout's timer); the leaves
        halted so far in this step. The limit only keeps a broken run from hanging."""
        assert self.a_halt.wait(timeout=30), "no leaf was halted"
        return list(self.book.halted)

    def tick(self) -> Step:
        # exactly once: tick_once() would tick again at once when a node asks to be woken up
        return self.book.step(self.tree.tick_exactly_once().name)


def theirs(tree: Node, scripts: Mapping[str, str], ticks: int) -> list[Step]:
    engine = Theirs(tree, scripts)
    return [engine.tick() for _ in range(ticks)]


def table(steps: list[Step]) -> str:
    """A run as a readable table (for assertion messages)."""
    return "\n".join(
        f"  tick {number}: {step.status:8} ticked [{step.ticked}] halted [{step.halted}]"
        for number, step in enumerate(steps, start=1)
    )
