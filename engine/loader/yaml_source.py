"""YAML parsed with the place of every value, safely.

PyYAML's composer gives nodes with marks; this module turns them into :class:`YMap`,
:class:`YList` and :class:`YScalar` that keep a :class:`Mark` each. Only plain YAML is
accepted: no Python tags, no duplicate keys, bounded size and alias expansion, UTF-8 only.
Nothing here evaluates code.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from engine.loader.problems import LoadError, Mark, Problem

MAX_FILE_BYTES = 1024 * 1024
MAX_NODES = 100_000

_STANDARD_TAGS = {
    "tag:yaml.org,2002:" + name
    for name in ("str", "int", "float", "bool", "null", "map", "seq", "timestamp")
}


@dataclass
class YScalar:
    value: Any
    mark: Mark


@dataclass
class YList:
    items: list[YValue]
    mark: Mark

    def __iter__(self) -> Iterator[YValue]:
        return iter(self.items)

    def __len__(self) -> int:
        return len(self.items)


@dataclass
class YMap:
    """A mapping whose keys are text; ``key_marks`` has the place of each key."""

    entries: dict[str, YValue]
    mark: Mark
    key_marks: dict[str, Mark] = field(default_factory=dict)

    def get(self, key: str) -> YValue | None:
        return self.entries.get(key)

    def __contains__(self, key: str) -> bool:
        return key in self.entries

    def items(self) -> Iterator[tuple[str, YValue]]:
        return iter(self.entries.items())

    def __len__(self) -> int:
        return len(self.entries)


YValue = YScalar | YList | YMap


def plain(value: YValue) -> Any:
    """The Python value without places (dicts, lists, scalars)."""
    if isinstance(value, YScalar):
        return value.value
    if isinstance(value, YList):
        return [plain(item) for item in value.items]
    return {key: plain(item) for key, item in value.entries.items()}


def describe(value: YValue) -> str:
    """How a value reads in a message: ``'three'``, ``a list``, ``a mapping``."""
    if isinstance(value, YMap):
        return "a mapping"
    if isinstance(value, YList):
        return "a list"
    return "nothing" if value.value is None else repr(value.value)


def _mark(file: str, yaml_mark: Any) -> Mark:
    return Mark(file, yaml_mark.line + 1, yaml_mark.column + 1)


def _hint_for(problem: str) -> str | None:
    if "\\t" in problem or "tab" in problem:
        return "indent with spaces, not tabs"
    if "mapping values are not allowed" in problem:
        return "put text containing ': ' in quotes"
    if "could not find expected ':'" in problem:
        return "each entry needs 'key: value'"
    if "expected <block end>" in problem or "did not find expected" in problem:
        return "check the indentation of this line and the one above"
    return None


class _Converter:
    def __init__(self, file: str) -> None:
        self.file = file
        self.count = 0
        self.problems: list[Problem] = []
        self.constructor = yaml.SafeLoader("")

    def convert(self, node: yaml.Node) -> YValue:
        self.count += 1
        if self.count > MAX_NODES:
            raise LoadError(
                [
                    Problem(
                        _mark(self.file, node.start_mark),
                        f"file expands to more than {MAX_NODES} values",
                        "remove deeply repeated aliases",
                    )
                ]
            )
        mark = _mark(self.file, node.start_mark)
        if node.tag not in _STANDARD_TAGS:
            tag = node.tag.replace("tag:yaml.org,2002:", "!!")
            self.problems.append(
                Problem(
                    mark, f"YAML tag {tag!r} is not allowed", "write plain values without '!' tags"
                )
            )
            return YScalar(None, mark)
        if isinstance(node, yaml.ScalarNode):
            try:
                value = self.constructor.construct_object(node, deep=True)
            except yaml.YAMLError as error:
                self.problems.append(Problem(mark, f"bad value: {error}"))
                value = None
            if node.tag.endswith(":timestamp"):
                value = str(node.value)
            return YScalar(value, mark)
        if isinstance(node, yaml.SequenceNode):
            return YList([self.convert(item) for item in node.value], mark)
        assert isinstance(node, yaml.MappingNode)
        entries: dict[str, YValue] = {}
        key_marks: dict[str, Mark] = {}
        for key_node, value_node in node.value:
            key_mark = _mark(self.file, key_node.start_mark)
            if not isinstance(key_node, yaml.ScalarNode) or key_node.tag.endswith(":merge"):
                self.problems.append(
                    Problem(
                        key_mark, "keys must be plain words", "remove '<<' merges and complex keys"
                    )
                )
                continue
            key = str(key_node.value)
            if key in entries:
                self.problems.append(
                    Problem(
                        key_mark,
                        f"duplicate key {key!r} (first at line {key_marks[key].line})",
                        "keep only one",
                    )
                )
                continue
            entries[key] = self.convert(value_node)
            key_marks[key] = key_mark
        return YMap(entries, mark, key_marks)


def read_text(path: Path, shown: str | None = None, *, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The file's text, or a LoadError: missing, unreadable, too big, not UTF-8."""
    name = shown or str(path)
    start = Mark(name, 1, 1)
    try:
        size = path.stat().st_size
        if path.is_dir():
            raise LoadError([Problem(start, "is a folder, not a file")])
        if size > max_bytes:
            raise LoadError(
                [
                    Problem(
                        start,
                        f"file is {size / 1024:.0f} KiB, more than the "
                        f"{max_bytes // 1024} KiB a vest YAML file may be",
                        "split it into subtrees",
                    )
                ]
            )
        data = path.read_bytes()
    except FileNotFoundError:
        raise LoadError([Problem(start, "file not found", "check the path")]) from None
    except PermissionError:
        raise LoadError(
            [Problem(start, "permission denied", "check the file's permissions")]
        ) from None
    except IsADirectoryError:
        raise LoadError([Problem(start, "is a folder, not a file")]) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        before = data[: error.start]
        line = before.count(b"\n") + 1
        column = error.start - (before.rfind(b"\n") + 1) + 1
        raise LoadError(
            [
                Problem(
                    Mark(name, line, column),
                    f"byte 0x{data[error.start]:02X} is not UTF-8 text",
                    "save the file as UTF-8",
                )
            ]
        ) from None


def parse_yaml(text: str, name: str) -> YValue | None:
    """Parse one YAML document keeping places; None for an empty document."""
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = _mark(name, mark) if mark is not None else Mark(name, 1, 1)
        problem = error.problem or "cannot be read"
        message = f"YAML syntax error: {problem}"
        if error.context:
            message += f" ({error.context})"
        raise LoadError([Problem(where, message, _hint_for(problem))]) from None
    except yaml.reader.ReaderError as error:
        before = text[: error.position]
        where = Mark(name, before.count("\n") + 1, error.position - (before.rfind("\n") + 1) + 1)
        char = error.character if isinstance(error.character, str) else chr(error.character)
        raise LoadError(
            [
                Problem(
                    where,
                    f"character U+{ord(char):04X} is not allowed in YAML",
                    "delete it or retype the line",
                )
            ]
        ) from None
    except yaml.composer.ComposerError as error:  # e.g. several documents in one file
        raise LoadError([Problem(Mark(name, 1, 1), f"YAML error: {error}")]) from None
    except yaml.YAMLError as error:
        raise LoadError([Problem(Mark(name, 1, 1), f"YAML error: {error}")]) from None
    if node is None:
        return None
    converter = _Converter(name)
    value = converter.convert(node)
    if converter.problems:
        raise LoadError(converter.problems)
    return value


def load_yaml(path: Path, shown: str | None = None) -> YValue | None:
    """Read and parse ``path``; messages name it as ``shown`` (default: the path)."""
    name = shown or str(path)
    return parse_yaml(read_text(path, name), name)
