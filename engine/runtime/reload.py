"""Hot reload: a changed tree file is validated and swapped in between ticks.

An invalid change keeps the running tree and reports every problem once; fixing the file
reloads it. Files are compared by modification time and size every ``check_every_s``
seconds of the engine clock. Only the files a tree uses are watched, and while an edit is
refused, the files that edit tried to read (a subtree it names may not exist yet).

The tick is sacred: on the robot, :meth:`TreeReloader.start` runs the slow part (stat,
read, parse, validate, build) on a thread of its own, and the scheduler hook only swaps
a tree that is ready, between ticks. Without a thread (tests, ``--fast``), the hook does
both itself, at its checks, so a run on a virtual clock stays deterministic.
"""

from __future__ import annotations

import logging
import queue
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import py_trees

from engine.clock import Clock
from engine.files.problems import LoadError, Mark, Problem
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.periodic import Periodic
from engine.runtime.scheduler import RunningTree
from engine.session.events import TreeReloaded
from engine.session.stream import SessionStream

_log = logging.getLogger("vest.reload")

Stamp = tuple[int, int] | None
STEADY_ATTEMPTS = 5
"""Loads of a file being saved meanwhile, before the check after leaves it to the next."""


def _stamp(path: Path) -> Stamp:
    try:
        info = path.stat()
    except (OSError, ValueError):
        return None
    return (info.st_mtime_ns, info.st_size)


@dataclass
class _Prepared:
    """A reload made ready beside the scheduler: the new tree, built, or why not."""

    tree: RunningTree
    definition: TreeDefinition | None
    built: py_trees.trees.BehaviourTree | None
    problem: LoadError | None


class TreeReloader:
    """A scheduler hook that reloads changed tree files (see the module's doc)."""

    def __init__(
        self,
        loader: TreeLoader,
        trees: list[RunningTree],
        clock: Clock,
        *,
        check_every_s: float = 1.0,
        on_reload: Callable[[str, LoadError | None], None] | None = None,
        session: SessionStream | None = None,
    ) -> None:
        self.loader = loader
        self.trees = trees
        self.clock = clock
        self.check_every_s = check_every_s
        self.on_reload = on_reload or _log_reload
        self.session = session
        """Where each reload (or refused change) is published as a TreeReloaded."""
        self._next_check_s = clock.now() + check_every_s
        self._stamps: dict[Path, dict[Path, Stamp]] = {
            tree.definition.path: _stamps(tree.definition.files or [tree.definition.path])
            for tree in trees
        }
        self._ready: queue.SimpleQueue[_Prepared] = queue.SimpleQueue()
        self._worker = Periodic(clock, check_every_s, self._queue_changed, name="vest-reload")

    # -- the scheduler's side -------------------------------------------------------------
    def __call__(self, now_s: float) -> None:
        if self._worker.running:
            self._swap_ready()
            return
        if now_s < self._next_check_s:
            return
        self._next_check_s = now_s + self.check_every_s
        self.check()

    def check(self) -> list[str]:
        """Reload every tree whose files changed, here and now; returns the names reloaded."""
        for prepared in self._prepare_changed():
            self._ready.put(prepared)
        return self._swap_ready()

    def _swap_ready(self) -> list[str]:
        reloaded: list[str] = []
        while True:
            try:
                prepared = self._ready.get_nowait()
            except queue.Empty:
                return reloaded
            problem = prepared.problem
            if problem is None and prepared.definition and prepared.built:
                try:
                    prepared.tree.swap(prepared.definition, prepared.built, keep_events=True)
                    reloaded.append(prepared.tree.name)
                except Exception as error:  # whatever went wrong, the running robot goes on
                    problem = _crashed(self.loader.shown(prepared.tree.definition.path), error)
            self.on_reload(prepared.tree.name, problem)
            if self.session is not None:
                why = "" if problem is None else _first_problem(problem)
                self.session.publish(TreeReloaded(self.clock.now(), prepared.tree.name, why))

    # -- the worker's side ------------------------------------------------------------------
    def start(self) -> None:
        """Check and prepare reloads on a thread of their own until :meth:`stop`."""
        self._worker.start()

    def stop(self) -> None:
        """End the worker (a reload it was preparing is dropped)."""
        self._worker.stop()

    def _queue_changed(self) -> None:
        """A round of the worker: the changed trees, prepared for the scheduler to swap."""
        for prepared in self._prepare_changed():
            self._ready.put(prepared)

    def _prepare_changed(self) -> list[_Prepared]:
        prepared = []
        for tree in self.trees:
            path = tree.definition.path
            watched = self._stamps[path]
            current = {file: _stamp(file) for file in watched}
            if current == watched:
                continue
            ready, read = self._prepare_steady(tree, current)
            # a refused version is remembered (reported once, not at every check); its
            # files are watched too: the fix may be in a subtree the running one lacks
            self._stamps[path] = {**current, **read} if ready.problem else read
            prepared.append(ready)
        return prepared

    def _prepare_steady(
        self, tree: RunningTree, before: dict[Path, Stamp]
    ) -> tuple[_Prepared, dict[Path, Stamp]]:
        """Load the changed files until what was read did not change while it was read
        (the files' stamps before and after a load agree), so a save that finished during
        a read is loaded too; (the load, the stamps of the files it read)."""
        for _ in range(STEADY_ATTEMPTS):
            ready, used = self._prepare(tree)
            after = _stamps(used)
            if all(before.get(file, after[file]) == after[file] for file in used):
                return ready, after
            before = after  # changed while being read: read it again
        return ready, dict.fromkeys(before)  # still being written: the next check reads it

    def _prepare(self, tree: RunningTree) -> tuple[_Prepared, list[Path]]:
        """Load and build the changed file, or say why the running tree is kept."""
        path = tree.definition.path
        used = [path]
        try:
            loaded, used = self.loader.load_watching(path)
            if isinstance(loaded, LoadError):
                return _Prepared(tree, None, None, loaded), used
            if loaded.name != tree.name:
                renamed = Problem(
                    loaded.root.mark,
                    f"the tree is renamed {tree.name!r} -> {loaded.name!r} while running",
                    "restart vest run to rename a tree",
                )
                return _Prepared(tree, None, None, LoadError([renamed])), used
            return _Prepared(tree, loaded, loaded.build(tree.context), None), used
        except Exception as error:  # whatever went wrong, the running robot goes on
            return _Prepared(tree, None, None, _crashed(self.loader.shown(path), error)), used


def _stamps(files: list[Path]) -> dict[Path, Stamp]:
    return {file: _stamp(file) for file in files}


def _crashed(shown: str, error: Exception) -> LoadError:
    _log.error("reloading %s failed", shown, exc_info=error)
    return LoadError(
        [Problem(Mark(shown, 1, 1), f"could not reload: {type(error).__name__}: {error}")]
    )


def _first_problem(error: LoadError) -> str:
    """The first problem of a refused change, and how many more there are."""
    first = str(error.problems[0]) if error.problems else str(error)
    more = len(error.problems) - 1
    return first + (f" (and {more} more)" if more > 0 else "")


def _log_reload(name: str, error: LoadError | None) -> None:
    if error is None:
        _log.info("reloaded %s", name)
    else:
        _log.error("kept the running %s; the changed file has problems:\n%s", name, error)
