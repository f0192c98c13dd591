"""The node registry: every node type the YAML may name, built-in or from plugins.

A registry is an object handed to the loader (no import-time globals). Other installed
packages add node types through the ``vest.nodes`` entry point group: the entry point
names either a Leaf subclass or a function ``register(registry)``.
"""

from __future__ import annotations

import difflib
import inspect
import logging
from collections.abc import Callable, Iterator
from importlib.metadata import EntryPoint, entry_points
from typing import Any

from engine.blackboard.catalogue import KeyCatalogue, KeySpec, default_catalogue
from engine.nodes.base import Leaf, leaf_type
from engine.nodes.spec import NodeType

ENTRY_POINT_GROUP = "vest.nodes"

_log = logging.getLogger("vest.plugins")


class NodeRegistry:
    """Node types by name, and the blackboard keys plugins bring (a plugin's sensor).

    Any kind of node may be added: a leaf class, or a :class:`NodeType` of any kind
    (composite and decorator too: its ``build`` gets the built children).
    """

    def __init__(self) -> None:
        self._types: dict[str, NodeType] = {}
        self._keys: dict[str, KeySpec] = {}
        self.plugin_errors: list[str] = []

    def add_key(self, spec: KeySpec) -> KeySpec:
        """A blackboard key for the catalogue (e.g. the reading of a plugin's sensor); a
        name the built-in catalogue or another plugin has is refused."""
        if default_catalogue().lookup(spec.name) is not None or spec.name in self._keys:
            raise ValueError(f"blackboard key {spec.name!r} already exists")
        self._keys[spec.name] = spec
        return spec

    @property
    def keys(self) -> list[KeySpec]:
        """The keys added with :meth:`add_key`."""
        return list(self._keys.values())

    def catalogue(self, base: KeyCatalogue | None = None) -> KeyCatalogue:
        """``base`` (default: the built-in catalogue) with the keys plugins added."""
        catalogue = base or default_catalogue()
        for spec in self._keys.values():
            catalogue.add(spec)
        return catalogue

    def add(self, node: type[Leaf] | NodeType, *, source: str = "vest", **bound: Any) -> NodeType:
        """Register a leaf class or a NodeType; a name already taken is an error naming both.

        ``bound``: keyword arguments each node of a leaf class is built with (its own
        services: ``registry.add(Greeter, speaker=my_speaker)``).
        """
        node_type = node if isinstance(node, NodeType) else leaf_type(node, source=source, **bound)
        self._check_free(node_type)
        self._types[node_type.name] = node_type
        return node_type

    def add_all(self, node_types: list[NodeType]) -> None:
        """Register all of ``node_types`` or, when one name is taken, none of them."""
        for node_type in node_types:
            self._check_free(node_type)
        for node_type in node_types:
            self._types[node_type.name] = node_type

    def _check_free(self, node_type: NodeType) -> None:
        holder = self._types.get(node_type.name)
        if holder is not None:
            raise ValueError(
                f"node type {node_type.name!r} from {node_type.source} is already "
                f"registered by {holder.source}"
            )

    def get(self, name: str) -> NodeType | None:
        return self._types.get(name)

    def suggest(self, name: str) -> str | None:
        close = difflib.get_close_matches(name, list(self._types), n=1, cutoff=0.5)
        if not close:
            lowered = {n.lower(): n for n in self._types}
            close = [lowered[name.lower()]] if name.lower() in lowered else []
        return close[0] if close else None

    @property
    def names(self) -> list[str]:
        return sorted(self._types)

    def __iter__(self) -> Iterator[NodeType]:
        return iter(sorted(self._types.values(), key=lambda t: (t.kind, t.name)))

    def __contains__(self, name: object) -> bool:
        return name in self._types

    def load_plugins(self, entries: list[EntryPoint] | None = None) -> None:
        """Add node types from installed packages; a broken plugin is noted, not fatal."""
        for entry in entries if entries is not None else entry_points(group=ENTRY_POINT_GROUP):
            source = entry.dist.name if entry.dist is not None else entry.value
            try:
                target = entry.load()
                if inspect.isclass(target) and issubclass(target, Leaf):
                    self.add(target, source=source)
                elif callable(target):
                    _call_register(target, self, source)
                else:
                    raise TypeError("is neither a Leaf subclass nor a register(registry) function")
            except Exception as error:  # one bad plugin must not stop the robot
                self.plugin_errors.append(f"plugin {entry.name} ({entry.value}): {error}")


def _call_register(register: Callable[..., object], registry: NodeRegistry, source: str) -> None:
    """Run a plugin's register(); its node types join ``registry`` only if all of it worked."""
    staging = _SourcedRegistry(registry, source)
    register(staging)
    if not staging.staged and not staging.staged_keys:
        raise ValueError("registered no node type and no key")
    for spec in staging.staged_keys:
        if default_catalogue().lookup(spec.name) is not None or spec.name in registry._keys:
            raise ValueError(f"blackboard key {spec.name!r} already exists")
    registry.add_all(staging.staged)
    for spec in staging.staged_keys:
        registry.add_key(spec)


class _SourcedRegistry:
    """What a plugin's register() receives: add() records the plugin as the source and
    stages the node type, so a plugin failing half-way leaves none of its node types behind."""

    def __init__(self, registry: NodeRegistry, source: str) -> None:
        self._registry = registry
        self._source = source
        self.staged: list[NodeType] = []
        self.staged_keys: list[KeySpec] = []

    def add_key(self, spec: KeySpec) -> KeySpec:
        self.staged_keys.append(spec)
        return spec

    def add(
        self, node: type[Leaf] | NodeType, *, source: str | None = None, **bound: Any
    ) -> NodeType:
        node_type = (
            node
            if isinstance(node, NodeType)
            else leaf_type(node, source=source or self._source, **bound)
        )
        self._registry._check_free(node_type)
        for staged in self.staged:
            if staged.name == node_type.name:
                raise ValueError(
                    f"node type {node_type.name!r} is registered twice by {staged.source}"
                )
        self.staged.append(node_type)
        return node_type


def builtin_registry() -> NodeRegistry:
    """The node types vest ships with."""
    from engine.nodes.actions import ACTIONS
    from engine.nodes.composites import COMPOSITES
    from engine.nodes.conditions import CONDITIONS
    from engine.nodes.counting import COUNTING
    from engine.nodes.decorators import DECORATORS
    from engine.nodes.dialog import DIALOG_NODES
    from engine.nodes.remote import REMOTE_NODES

    registry = NodeRegistry()
    for node_type in (*COMPOSITES, *DECORATORS, *COUNTING):
        registry.add(node_type)
    for leaf in (*CONDITIONS, *ACTIONS, *DIALOG_NODES, *REMOTE_NODES):
        registry.add(leaf)
    return registry


def default_registry(*, plugins: bool = True) -> NodeRegistry:
    """Built-in node types plus those of installed plugins (a broken one is logged)."""
    registry = builtin_registry()
    if plugins:
        registry.load_plugins()
        for error in registry.plugin_errors:
            _log.warning("%s", error)
    return registry
