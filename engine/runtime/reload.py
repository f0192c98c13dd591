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
from engine.files.problems import LoadError, Mark, Problem
from engine.loader.tree_file import TreeDefinition, TreeLoader
from engine.runtime.scheduler import RunningTree

_log = logging.getLogger("vest.reload")

Stamp = tuple[int, int] | None
MAX_WATCHED = 500


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
            path = tree.definition.path
            old = self._stamps[path]
            current = {file: _stamp(file) for file in old}
            if current == old:
                continue
            # the refused version is remembered (reported once, not at every check), and
            # while it is refused every YAML file near it is watched: the fix may be in a
            # subtree the running version did not include
            self._stamps[path] = {**current, **_stamps_near(path)}
            problem = self._reload(tree)
            self.on_reload(tree.name, problem)
            if problem is None:
                self._stamps[path] = self._stamps_of(tree.definition)
                reloaded.append(tree.name)
        return reloaded

    def _reload(self, tree: RunningTree) -> LoadError | None:
        """Swap in the changed file, or say why the running tree is kept."""
        shown = self.loader.shown(tree.definition.path)
        try:
            definition = self.loader.load(tree.definition.path)
            if definition.name != tree.name:
                return LoadError(
                    [
                        Problem(
                            definition.root.mark,
                            f"the tree is renamed "
                            f"{tree.name!r} -> {definition.name!r} while running",
                            "restart vest run to rename a tree",
                        )
                    ]
                )
            tree.replace(definition)
        except LoadError as error:
            return error
        except Exception as error:  # whatever went wrong, the running robot goes on
            _log.exception("reloading %s failed", shown)
            return LoadError(
                [Problem(Mark(shown, 1, 1), f"could not reload: {type(error).__name__}: {error}")]
            )
        return None


def _stamps_near(tree_file: Path) -> dict[Path, Stamp]:
    """Every YAML file in the tree file's folder and below (bounded)."""
    found: dict[Path, Stamp] = {}
    try:
        for file in sorted(tree_file.parent.rglob("*.yaml"))[:MAX_WATCHED]:
            found[file] = _stamp(file)
    except OSError:
        pass
    return found


def _log_reload(name: str, error: LoadError | None) -> None:
    if error is None:
        _log.warning("reloaded %s", name)
    else:
        _log.error("kept the running %s; the changed file has problems:\n%s", name, error)
