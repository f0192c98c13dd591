"""Node types: the registry, the base classes for new leaves, and the built-in nodes."""

from py_trees.common import Status

from engine.nodes.base import Condition, Leaf, ServiceAction
from engine.nodes.registry import NodeRegistry, builtin_registry, default_registry
from engine.nodes.spec import NodeType
from engine.remote_commands import Color
from engine.values.params import (
    AnyValue,
    Boolean,
    Choice,
    Integer,
    Key,
    ListOf,
    Number,
    Param,
    Scalar,
    Text,
)
from engine.values.templates import Template

__all__ = [
    "AnyValue",
    "Boolean",
    "Choice",
    "Color",
    "Condition",
    "Integer",
    "Key",
    "Leaf",
    "ListOf",
    "NodeRegistry",
    "NodeType",
    "Number",
    "Param",
    "Scalar",
    "ServiceAction",
    "Status",
    "Template",
    "Text",
    "builtin_registry",
    "default_registry",
]
