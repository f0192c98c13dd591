"""Hot reload: a changed tree file is validated and swapped in between ticks.

An invalid change keeps the running tree and reports every problem once; fixing the file
reloads it. Files are compared by modification time and size, checked every
``check_every_s`` seconds of the engine clock.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

from engine.clock import Clock
from engine.loader.problems import LoadError
from engine.loader.tree_file import TreeDefinition, TreeLoader
from engine.runtime.scheduler import RunningTree

_log = logging.getLogger("vest.reload")

Stamp = tuple[int, int] | None


def _stamp(path: Path) -> Stamp:
    try:
        info = path.stat()
    except OSError:
        return None
    return (info.st_mtime_ns, info.st_size)


class TreeReloader:
    """A scheduler hook that reloads changed tree files."""

    def __init__(
        self,
        loader: TreeLoader,
        trees: list[RunningTree],
        clock: Clock,
        *,
        check_every_s: float = 1.0,
        on_reload: Callable[[str, LoadError | None], None] | None = None,
    ) -> None:
        self.loader = loader
        self.trees = trees
        self.check_every_s = check_every_s
        self.on_reload = on_reload or _log_reload
        self._next_check_s = clock.now() + check_every_s
        self._stamps: dict[Path, dict[Path, Stamp]] = {
            tree.definition.path: self._stamps_of(tree.definition) for tree in trees
        }

    @staticmethod
    def _stamps_of(definition: TreeDefinition) -> dict[Path, Stamp]:
        return {path: _stamp(path) for path in definition.files or [definition.path]}

    def __call__(self, now_s: float) -> None:
        if now_s < self._next_check_s:
            return
        self._next_check_s = now_s + self.check_every_s
        self.check()

    def check(self) -> list[str]:
        """Reload every tree whose files changed; returns the names reloaded."""
        reloaded = []
        for tree in self.trees:
            old = self._stamps[tree.definition.path]
            current = {path: _stamp(path) for path in old}
            if current == old:
                continue
            # remember the bad version so it is reported once, not at every check
            self._stamps[tree.definition.path] = current
            try:
                definition = self.loader.load(tree.definition.path)
            except LoadError as error:
                self.on_reload(tree.name, error)
                continue
            tree.replace(definition)
            self._stamps[tree.definition.path] = self._stamps_of(definition)
            reloaded.append(tree.name)
            self.on_reload(tree.name, None)
        return reloaded


def _log_reload(name: str, error: LoadError | None) -> None:
    if error is None:
        _log.warning("reloaded %s", name)
    else:
        _log.error("kept the running %s; the changed file has problems:\n%s", name, error)
