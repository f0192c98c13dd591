"""Composite nodes: Sequence, Selector, Parallel (py_trees' own, with documented defaults)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import py_trees

from engine.nodes.context import TreeContext
from engine.nodes.parallel import Parallel
from engine.nodes.spec import NodeType
from engine.values.params import Boolean, Choice, Param

_MEMORY_SEQUENCE = Param(
    "memory",
    Boolean(),
    True,
    "true: a running child is resumed next tick without re-checking the children before "
    "it (the robot finishes what it started); false: every tick starts from the first child",
)
_MEMORY_SELECTOR = Param(
    "memory",
    Boolean(),
    False,
    "false: every tick tries the children from the first again, so a higher-priority "
    "child can take over; true: a running child is resumed",
)


def _sequence(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return py_trees.composites.Sequence(name=name, memory=args.memory, children=children)


def _selector(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return py_trees.composites.Selector(name=name, memory=args.memory, children=children)


def _parallel(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return Parallel(name, children, succeed_when=args.succeed_when, synchronise=args.synchronise)


COMPOSITES = (
    NodeType(
        "Sequence",
        "composite",
        """Do the children in order, one after the other.

        SUCCESS when every child succeeded; FAILURE as soon as one fails; RUNNING while
        the current child runs.""",
        (_MEMORY_SEQUENCE,),
        _sequence,
    ),
    NodeType(
        "Selector",
        "composite",
        """Try the children in order until one does not fail (a fallback).

        SUCCESS as soon as one child succeeds; FAILURE when every child failed; RUNNING
        while the current child runs.""",
        (_MEMORY_SELECTOR,),
        _selector,
    ),
    NodeType(
        "Parallel",
        "composite",
        """Tick every child each tick, side by side (speak while the LEDs light up).

        A child that fails never cuts the others short: the robot still says what it
        meant to say when the LEDs are unplugged. SUCCESS when all children (or one, with
        succeed_when: one) succeeded; FAILURE when every child has finished and one
        failed (with succeed_when: one, when all failed); RUNNING otherwise.""",
        (
            Param(
                "succeed_when",
                Choice(("all", "one")),
                "all",
                "all: succeed when every child succeeded; one: as soon as one did (the "
                "children after it are not ticked, those still running are halted)",
            ),
            Param(
                "synchronise",
                Boolean(),
                True,
                "with succeed_when: all, do not tick again a child that already succeeded",
            ),
        ),
        _parallel,
    ),
)
