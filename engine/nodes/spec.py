"""Node type declarations: what the loader, ``vest nodes`` and the docs are made from.

A :class:`NodeType` names a node, its kind, its parameters and the blackboard keys it
reads and writes, and knows how to build the py_trees behaviour. Leaf nodes written as
classes (subclasses of :class:`~engine.nodes.base.Leaf`) are turned into a NodeType by
:func:`engine.nodes.base.leaf_type`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Literal

import py_trees

from engine.nodes.context import TreeContext
from engine.services.turns import FACE_LEDS, SPEAKER, joint_resource
from engine.values.param_problems import CheckContext, ParamIssue
from engine.values.params import Key, ListOf, Param
from engine.values.templates import CompiledTemplate

Kind = Literal["composite", "decorator", "condition", "action"]
KINDS: tuple[Kind, ...] = ("composite", "decorator", "condition", "action")

Builder = Callable[
    [str, SimpleNamespace, list[py_trees.behaviour.Behaviour], TreeContext],
    py_trees.behaviour.Behaviour,
]
ExtraCheck = Callable[[Mapping[str, Any], CheckContext], list[ParamIssue]]
"""Cross-parameter checks: returns (parameter or None, message, hint) per problem."""

ITS_JOINT = "its joint"
"""A node that uses this moves the joint its ``joint`` parameter names (neck by default)."""
ANY_JOINT = joint_resource("any")
"""A node that uses this may move any joint (a remote command)."""
RESOURCES = (SPEAKER, FACE_LEDS, ITS_JOINT, ANY_JOINT)
"""What a node type may declare it uses of the robot (:attr:`NodeType.uses`): the
priority check and the robot checks read it, so a plugin's node takes part as a built-in
one does."""


@dataclass(frozen=True)
class NodeType:
    """A node type the YAML can name."""

    name: str
    kind: Kind
    doc: str
    params: tuple[Param[Any], ...]
    build: Builder
    check: ExtraCheck | None = None
    fixed_reads: tuple[str, ...] = ()
    fixed_writes: tuple[str, ...] = ()
    source: str = "vest"
    uses: tuple[str, ...] = ()
    """What its nodes use of the robot, of :data:`RESOURCES`."""

    def __post_init__(self) -> None:
        if isinstance(self.uses, str) or not isinstance(self.uses, tuple):
            raise TypeError(
                f"{self.name} uses {self.uses!r}: a tuple of what it uses, e.g. uses = (SPEAKER,)"
            )
        if ITS_JOINT in self.uses and self.param("joint") is None:
            raise TypeError(
                f"{self.name} uses its joint but has no 'joint' parameter naming it; add "
                'joint = Param("joint", Text(), "neck", ...) or declare ANY_JOINT'
            )
        unknown = [use for use in self.uses if use not in RESOURCES]
        if unknown:
            raise TypeError(
                f"{self.name} uses {unknown}: a node uses some of SPEAKER, FACE_LEDS "
                "(engine.services.turns), ITS_JOINT (the joint its 'joint' parameter names) "
                "and ANY_JOINT (engine.nodes.spec)"
            )

    @property
    def moves_its_joint(self) -> bool:
        return ITS_JOINT in self.uses

    def resources(self, args: Mapping[str, Any]) -> set[str]:
        """What a node of this type with these arguments can want of the robot: the
        speaker, the face LEDs, a joint by name (``neck joint``), any joint."""
        used = {use for use in self.uses if use != ITS_JOINT}
        if self.moves_its_joint:
            used.add(joint_resource(str(args.get("joint", "neck"))))
        return used

    @property
    def children(self) -> Literal["none", "one", "many"]:
        return {"composite": "many", "decorator": "one"}.get(self.kind, "none")  # type: ignore[return-value]

    @property
    def summary(self) -> str:
        return self.doc.strip().splitlines()[0] if self.doc.strip() else ""

    def param(self, name: str) -> Param[Any] | None:
        for param in self.params:
            if param.name == name:
                return param
        return None

    def keys(self, args: Mapping[str, Any]) -> tuple[list[str], list[str]]:
        """The blackboard keys a node with these (converted) arguments reads and writes."""
        reads, writes = list(self.fixed_reads), list(self.fixed_writes)
        for param in self.params:
            value = args.get(param.name)
            if value is None:
                continue
            if isinstance(value, CompiledTemplate):
                reads.extend(value.keys)
                continue
            key_type = param.type.item if isinstance(param.type, ListOf) else param.type
            if not isinstance(key_type, Key):
                continue
            values = value if isinstance(value, list) else [value]
            (writes if key_type.access == "write" else reads).extend(values)
        return reads, writes
