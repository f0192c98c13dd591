"""What a built node may use while the tree runs: clock, blackboard, services, dialogs."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from engine.blackboard.board import Blackboard
from engine.clock import Clock
from engine.services.actions import TreeActions
from engine.session.stream import SessionStream

if TYPE_CHECKING:
    from engine.dialogs.library import DialogLibrary

NodeErrorHandler = Callable[[str, str, BaseException], None]
"""Called as (tree name, node path, error) when a node raised and was made FAILURE."""

NodeWarningHandler = Callable[[str, str, str], None]
"""Called as (tree name, node path, message) when a node noticed something went amiss
without failing (e.g. events it never saw because too many came at once)."""

_log = logging.getLogger("vest.tree")


class NodeErrorLog:
    """Logs a node's error once per node and kind of error, then only a running count.

    A node that fails the same way at every tick (a missing ``reads`` declaration, a
    broken plugin) would otherwise log one line per tick: 601 lines in a minute. The
    first time is logged in full; the count at 10, 100, 1000... ``counts`` keeps them all.
    """

    def __init__(self, logger: logging.Logger = _log) -> None:
        self.logger = logger
        self.counts: dict[tuple[str, str, str], int] = {}

    def __call__(self, tree: str, path: str, error: BaseException) -> None:
        kind = type(error).__name__
        key = (tree, path, kind)
        count = self.counts.get(key, 0) + 1
        self.counts[key] = count
        if count == 1:
            self.logger.error("%s: node %s failed: %s: %s", tree, path, kind, error)
        elif _is_power_of_ten(count):
            self.logger.error("%s: node %s failed with %s %d times so far", tree, path, kind, count)


def _is_power_of_ten(count: int) -> bool:
    while count % 10 == 0:
        count //= 10
    return count == 1


def log_node_error(tree: str, path: str, error: BaseException) -> None:
    """Log one node error in full (a robot shares one :class:`NodeErrorLog` instead)."""
    _log.error("%s: node %s failed: %s: %s", tree, path, type(error).__name__, error)


def log_node_warning(tree: str, path: str, message: str) -> None:
    _log.warning("%s: node %s: %s", tree, path, message)


@dataclass
class TreeContext:
    """One tree's view of the robot. Injected into every node the loader builds."""

    tree: str
    clock: Clock
    blackboard: Blackboard
    actions: TreeActions
    dialogs: DialogLibrary | None = None
    on_node_error: NodeErrorHandler = field(default=log_node_error)
    on_node_warning: NodeWarningHandler = field(default=log_node_warning)
    session: SessionStream | None = None
    """Where nodes tell what happened that only they know (a sentence no rule matched)."""
