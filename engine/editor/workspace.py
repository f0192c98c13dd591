"""The folder ``vest edit`` works in: what it lists, reads, checks and saves.

Only files inside the folder are read or written (a name that leads out of it, through
``..`` or a link, is refused), only ``.yaml`` files, and a save is checked first:

- the file must be as it was when the page read it (its version, a hash of its bytes):
  a file changed on disk meanwhile is never overwritten silently;
- the new text is checked as ``vest validate`` checks it, in its place among the
  folder's other files (its subtrees, its dialogs, the robot's pads and joints); a text
  with problems is never saved over a file without them unless the person said so;
- the text is written whole or not at all (a temporary file beside it, then renamed), so a
  robot running ``vest run`` on the folder reloads either the old tree or the new one;
- a file is compared and written under a lock of its own: of saves sent at once from one
  version, one is written and the others are told the file changed (409);
- nothing outside the folder is read by the checks, nor by a try (a subtree that leads
  out of it is a problem, named by the path written, never read).
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import re
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import yaml
from ruamel.yaml.comments import CommentedMap

from engine.dialogs.library import OUTSIDE
from engine.editor import round_trip
from engine.files.problems import LoadError, Problem
from engine.files.whole_file import write_whole
from engine.files.yaml_source import read_bytes, resolved
from engine.files.yaml_values import plain
from engine.loader.substitution import load_profile
from engine.loader.tree_definition import TreeDefinition
from engine.nodes.registry import NodeRegistry
from engine.session.json_values import json_value

LISTED = ("trees", "dialogs")
"""The folders listed when the folder holds them (a project); else the folder itself."""
MAX_FILE_BYTES = 1_000_000


SETTING_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")
"""A tree's setting (a ``${name}``), as a profile names it."""


class EditRefused(Exception):  # noqa: N818 - a refusal told to the page, not a failure
    """Why a read or save is refused: ``status`` is the HTTP status the page gets."""

    def __init__(self, status: int, message: str, problems: list[dict[str, Any]] | None = None):
        super().__init__(message)
        self.status = status
        self.problems = problems or []


@dataclass(frozen=True)
class Saved:
    version: str
    problems: list[dict[str, Any]]


def version_of(data: bytes) -> str:
    """A file's version as the page holds it: the hash of its bytes."""
    return hashlib.sha256(data).hexdigest()[:16]


class Checks(Protocol):
    """The checks of ``vest validate`` (engine.cli.edit_checks gives them): what a file is,
    and what is wrong with a text in a file's place."""

    def kind_of(self, path: Path) -> str:
        """tree, subtree, profile, dialog, buttons, scenario, robot config, other, or
        unreadable."""
        ...

    def check(self, path: Path, text: str) -> tuple[list[Problem], TreeDefinition | None]:
        """The problems of ``path`` if it held ``text``, and the tree it makes (None: not
        a tree without problems)."""
        ...


class Workspace:
    """The folder being edited: ``registry`` knows the nodes, ``checks`` what is wrong."""

    def __init__(self, folder: Path, registry: NodeRegistry, checks: Checks) -> None:
        self.folder = folder.resolve()
        self.registry = registry
        self.checks = checks
        mask = os.umask(0)  # read once, at the start, before any thread writes
        os.umask(mask)
        self._locks: dict[Path, threading.Lock] = {}
        self._locks_lock = threading.Lock()
        self.new_mode = 0o666 & ~mask
        """A new file's permissions: what the person's umask gives (0644 as a rule)."""

    # -- where ----------------------------------------------------------------------------
    def path_of(self, name: str) -> Path:
        """The file ``name`` (relative to the folder); EditRefused when it is not a YAML
        file inside the folder."""
        if not name or "\x00" in name or Path(name).is_absolute():
            raise EditRefused(400, f"{name!r}: give a file's name inside the folder")
        path = (self.folder / name).resolve()
        if not path.is_relative_to(self.folder):
            raise EditRefused(403, f"{name}: outside the folder the editor works in")
        if path.suffix not in (".yaml", ".yml"):
            raise EditRefused(400, f"{name}: the editor edits .yaml files only")
        return path

    def files(self) -> list[dict[str, str]]:
        """Every YAML file listed, with what it is: tree, subtree, profile, dialog, ..."""
        roots = [self.folder / name for name in LISTED if (self.folder / name).is_dir()]
        found: list[dict[str, str]] = []
        for root in roots or [self.folder]:
            for path in sorted(root.rglob("*.y*ml")):
                shown = path.relative_to(self.folder)
                if any(part.startswith(".") for part in shown.parts):
                    continue
                if not path.resolve().is_relative_to(self.folder):
                    continue  # a link out of the folder is not listed
                found.append({"file": shown.as_posix(), "kind": self.checks.kind_of(path)})
        return found

    def priorities(self) -> dict[str, int]:
        """Each tree's priority by its name (0 when it gives none), for the page to say
        what a priority interrupts; a file that does not read as a tree is left out."""
        found: dict[str, int] = {}
        for listed in self.files():
            if listed["kind"] != "tree":
                continue
            try:
                document = yaml.safe_load(self.read(listed["file"])[0])
            except (EditRefused, yaml.YAMLError):
                continue
            if isinstance(document, dict) and isinstance(document.get("name"), str):
                priority = document.get("priority", 0)
                found[document["name"]] = priority if isinstance(priority, int) else 0
        return found

    def profiles(self) -> tuple[dict[str, dict[str, Any]], list[str]]:
        """What each profile (``trees/profiles/*.yaml``) sets: {profile: {param: value}},
        and for each profile that does not load, its first problem with its place."""
        found: dict[str, dict[str, Any]] = {}
        problems: list[str] = []
        folder = self.folder / "trees" / "profiles"
        for path in sorted(folder.glob("*.y*ml")) if folder.is_dir() else ():
            if not path.resolve().is_relative_to(self.folder):
                continue  # a link out of the folder is not read
            try:
                profile = load_profile(path, path.relative_to(self.folder).as_posix())
            except LoadError as error:
                problems.append(f"{error.problems[0]} (the editor leaves this profile out)")
                continue
            values = {name: plain(given.value) for name, given in profile.params.items()}
            found[profile.name] = json_value(values)  # a NaN or infinity is shown as nothing
        return found, problems

    def set_in_profile(self, profile: str, setting: str, value: Any) -> None:
        """The profile called ``profile`` sets ``setting`` to ``value`` (None: it no longer
        sets it, the tree's own value holds), written in place in its file (its comments
        kept); EditRefused when there is no such profile or the value is not one."""
        if not isinstance(setting, str) or not SETTING_NAME.fullmatch(setting):
            raise EditRefused(400, "setting: letters, digits and _, e.g. left_squeeze_n")
        if value is not None and not isinstance(value, str | int | float | bool):
            raise EditRefused(400, f"{setting}: a number, a word or true/false")
        if isinstance(value, float) and not math.isfinite(value):
            raise EditRefused(400, f"{setting}: a number, not {value}")
        folder = self.folder / "trees" / "profiles"
        for path in sorted(folder.glob("*.y*ml")) if folder.is_dir() else ():
            name = path.relative_to(self.folder).as_posix()
            try:
                found = load_profile(path, name)
            except LoadError:
                continue
            if found.name == profile:
                break
        else:
            raise EditRefused(404, f"no profile {str(profile)[:40]!r} in trees/profiles/")
        text, version = self.read(name)
        document, style = round_trip.read(text)
        params = document.get("params")
        if not isinstance(params, CommentedMap):
            params = document["params"] = CommentedMap()
        if value is None:
            params.pop(setting, None)
        else:
            params[setting] = round_trip.yaml_value(value)
        self.save(name, round_trip.dumped(document, style, round_trip.newline_of(text)), version)

    # -- read, check, save ----------------------------------------------------------------
    def read(self, name: str) -> tuple[str, str]:
        """The file's text and version; EditRefused when there is none or it is too big."""
        path = self.path_of(name)
        if not path.exists() and not path.is_symlink():
            raise EditRefused(404, f"{name}: no such file")
        try:  # the one reader of a person's files: regular files only (never a FIFO), sized
            data = read_bytes(path, name, max_bytes=MAX_FILE_BYTES)
        except LoadError as error:
            raise EditRefused(400, str(error.problems[0])) from None
        try:
            return data.decode("utf-8"), version_of(data)
        except UnicodeDecodeError:
            raise EditRefused(400, f"{name}: not UTF-8 text") from None

    def check(self, name: str, text: str) -> list[dict[str, Any]]:
        """What ``vest validate`` would say of ``name`` if it held ``text``: each problem
        with its line, column, message and hint (empty: none)."""
        return self.checked(name, text)[0]

    def checked(self, name: str, text: str) -> tuple[list[dict[str, Any]], TreeDefinition | None]:
        """:meth:`check`'s problems, and the tree ``text`` makes (None: not a good tree)."""
        path = self.path_of(name)
        problems, tree = self.checks.check(path, text)
        found = [_described(p, path, self.folder) for p in dict.fromkeys(problems)]
        return found, tree if not found else None

    def leads_outside(self, name: str, text: str) -> str | None:
        """Why ``text`` cannot be run as ``name`` (a subtree outside the folder), or None."""
        for problem in self.check(name, text):
            if problem["message"] == OUTSIDE:
                return f"{problem['file']}: {OUTSIDE} (keep subtrees inside the folder)"
        return None

    def _lock_of(self, path: Path) -> threading.Lock:
        with self._locks_lock:
            return self._locks.setdefault(path, threading.Lock())

    def save(
        self, name: str, text: str, version: str | None, *, over_problems: bool = False
    ) -> Saved:
        """Write ``text`` to ``name`` if the file is still at ``version`` (None: a new
        file, which must not exist yet); EditRefused (409) when it changed meanwhile, or
        when ``text`` makes problems the folder did not have (in this file, or a new
        file's in itself) and ``over_problems`` is False. Compared and written under the
        file's lock."""
        path = self.path_of(name)
        with self._lock_of(path):
            return self._save(path, name, text, version, over_problems)

    def _save(
        self, path: Path, name: str, text: str, version: str | None, over_problems: bool
    ) -> Saved:
        on_disk: str | None
        try:
            on_disk, current = self.read(name)
        except EditRefused as refused:
            if refused.status != 404:
                raise
            on_disk, current = None, None
        if current != version:
            if version is None:
                why = "there is a file of that name already: open it, or give the new one another"
                raise EditRefused(409, f"{name}: {why}")
            why = "changed on disk since it was opened; open it again to see the change"
            raise EditRefused(409, f"{name}: {why}")
        problems = self.check(name, text)
        if problems and not over_problems:
            before = (
                {p["text"] for p in self.check(name, on_disk)} if on_disk is not None else set()
            )
            made = [p for p in problems if p["text"] not in before and (on_disk or p["here"])]
            if made:  # what this change would break, not what was broken before it
                raise EditRefused(
                    409,
                    f"{name}: the change has {len(made)} problem"
                    f"{'s' if len(made) != 1 else ''} ({made[0]['text']}"
                    f"{', ...' if len(made) > 1 else ''}), which would keep vest run from "
                    "starting with this folder (save anyway to keep it unfinished)",
                    made,
                )
        data = text.encode("utf-8")
        path.parent.mkdir(parents=True, exist_ok=True)
        write_whole(path, data, mode=None if path.exists() else self.new_mode)
        return Saved(version_of(data), problems)


def _described(problem: Problem, path: Path, folder: Path) -> dict[str, Any]:
    mark = problem.mark
    here = resolved(Path(mark.file)) == resolved(path) or mark.file == str(path)
    shown = mark.file
    with contextlib.suppress(ValueError):
        shown = resolved(Path(mark.file)).relative_to(folder).as_posix()
    return {
        "file": shown,
        "here": here,
        "line": mark.line,
        "column": mark.column,
        "message": problem.message,
        "hint": problem.hint,
        "text": str(problem),
    }
