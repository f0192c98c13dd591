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
