"""The YAML files one command reads, each parsed once.

`vest validate` looks at a file to tell what it is, loads it as a tree, checks its name
against its neighbours' and loads the subtrees several trees share: without this, a big
tree was parsed three times. A file is parsed again only when it changed (its size,
modification time or inode differ), so a long-lived loader (hot reload) sees every edit.
"""

from __future__ import annotations

import os
from pathlib import Path

from engine.files.problems import LoadError
from engine.files.yaml_source import YValue, load_yaml, resolved

_Key = tuple[str, str | None, int, int, int]


class ParsedFiles:
    """A cache of parsed YAML files, values and problems alike, keyed as said above."""

    def __init__(self) -> None:
        self._parsed: dict[_Key, YValue | LoadError | None] = {}

    def load(self, path: Path, shown: str | None = None) -> YValue | None:
        """:func:`~engine.files.yaml_source.load_yaml`, answered from the cache when the
        file has not changed since it was parsed (the same LoadError again if it failed)."""
        try:
            info = os.stat(path)
        except (OSError, ValueError):
            return load_yaml(path, shown)  # words why the file cannot be read
        key = (str(resolved(path)), shown, info.st_size, info.st_mtime_ns, info.st_ino)
        if key not in self._parsed:
            try:
                self._parsed[key] = load_yaml(path, shown)
            except LoadError as error:
                self._parsed[key] = error
        found = self._parsed[key]
        if isinstance(found, LoadError):
            raise LoadError(found.problems)
        return found
