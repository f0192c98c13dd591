"""What a built node may use while the tree runs: clock, blackboard, services, dialogs."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from engine.blackboard.board import Blackboard
from engine.clock import Clock
from engine.services.actions import TreeActions

if TYPE_CHECKING:
    from engine.dialogs.library import DialogLibrary

NodeErrorHandler = Callable[[str, str, BaseException], None]
"""Called as (tree name, node path, error) when a node raised and was made FAILURE."""

NodeWarningHandler = Callable[[str, str, str], None]
"""Called as (tree name, node path, message) when a node noticed something went amiss
without failing (e.g. events it never saw because too many came at once)."""

_log = logging.getLogger("vest.tree")


def log_node_error(tree: str, path: str, error: BaseException) -> None:
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
