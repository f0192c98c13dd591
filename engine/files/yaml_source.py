"""YAML parsed with the place of every value, safely.

PyYAML's composer gives nodes with marks; this module turns them into :class:`YMap`,
:class:`YList` and :class:`YScalar` that keep a :class:`Mark` each. Only plain YAML is
accepted: no Python tags, no duplicate keys, bounded size, nesting and alias expansion, no
alias inside its own anchor, UTF-8 only. Nothing here evaluates code, and whatever a file
holds, the answer is a value or a :class:`LoadError` with places, never another exception.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path
from typing import Any

import yaml

from engine.files.problems import LoadError, Mark, Problem
from engine.files.yaml_events import STANDARD_TAGS, NeedsCarefulReading, compose_fast
from engine.files.yaml_slips import explain, hint_for
from engine.files.yaml_values import (
    LONE_SURROGATE,
    YList,
    YMap,
    YScalar,
    YValue,
    describe,
    plain,
    scalar_value,
)

__all__ = [
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_NODES",
    "YList",
    "YMap",
    "YScalar",
    "YValue",
    "describe",
    "load_yaml",
    "parse_yaml",
    "plain",
    "read_text",
    "resolved",
]

MAX_FILE_BYTES = 1024 * 1024
MAX_NODES = 100_000
MAX_DEPTH = 100
"""Values nested deeper than this are refused (a tree 50 composites deep is already far
beyond what anyone writes; deeper ones would exhaust Python's stack)."""


def _mark(file: str, yaml_mark: Any) -> Mark:
    return Mark(file, yaml_mark.line + 1, yaml_mark.column + 1)


class _Refused(Exception):  # noqa: N818 - a problem found while composing, not a failure
    def __init__(self, mark: Any, message: str, hint: str) -> None:
        super().__init__(message)
        self.mark = mark
        self.message = message
        self.hint = hint


class _Composer(yaml.SafeLoader):
    """PyYAML's safe loader that also refuses deep nesting and an alias inside its anchor
    (``root: &x {Sequence: [*x]}``), with the place, before anything recurses on them."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self._depth = 0
        self._open_anchors: set[str] = set()

    def compose_node(self, parent: Any, index: Any) -> Any:
        event = self.peek_event()  # type: ignore[no-untyped-call]
        if isinstance(event, yaml.AliasEvent):
            if event.anchor in self._open_anchors:
                raise _Refused(
                    event.start_mark,
                    f"alias *{event.anchor} refers to itself: it is inside &{event.anchor}",
                    "an alias repeats a value defined before it, never the value it is in",
                )
            return super().compose_node(parent, index)
        self._depth += 1
        if self._depth > MAX_DEPTH:
            raise _Refused(
                event.start_mark,
                f"values are nested more than {MAX_DEPTH} levels deep here",
                "nest less; a tree can move a part into its own file with Subtree",
            )
        anchor = event.anchor
        if anchor is not None:
            self._open_anchors.add(anchor)
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1
            if anchor is not None:
                self._open_anchors.discard(anchor)


class _Converter:
    def __init__(self, file: str) -> None:
        self.file = file
        self.count = 0
        self.problems: list[Problem] = []
        self.constructor = yaml.SafeLoader("")

    def refuse_surrogates(self, text: str, mark: Mark) -> None:
        found = LONE_SURROGATE.search(text)
        if found:
            self.problems.append(
                Problem(
                    mark,
                    f"\\u{ord(found.group()):04X} is half of a character pair, not a character",
                    "remove the escape, or write the character itself",
                )
            )

    def convert(self, node: yaml.Node, depth: int = 1) -> YValue:
        self.count += 1
        mark = _mark(self.file, node.start_mark)
        if self.count > MAX_NODES:
            raise LoadError(
                [
                    Problem(
                        mark,
                        f"file expands to more than {MAX_NODES} values",
                        "remove deeply repeated aliases",
                    )
                ]
            )
        if depth > MAX_DEPTH:  # aliases of nested values inside nested values
            raise LoadError(
                [
                    Problem(
                        mark,
                        f"with its aliases, values are nested more than {MAX_DEPTH} levels deep",
                        "use fewer aliases inside aliases",
                    )
                ]
            )
        if node.tag not in STANDARD_TAGS:
            tag = node.tag.replace("tag:yaml.org,2002:", "!!")
            self.problems.append(
                Problem(
                    mark, f"YAML tag {tag!r} is not allowed", "write plain values without '!' tags"
                )
            )
            return YScalar(None, mark)
        if isinstance(node, yaml.ScalarNode):
            self.refuse_surrogates(node.value, mark)
            try:
                value = scalar_value(self.constructor, node.tag, node.value, node.style)
            except (yaml.YAMLError, ValueError, OverflowError) as error:
                # e.g. an integer of more digits than Python converts
                self.problems.append(Problem(mark, f"bad value: {error}"))
                value = None
            return YScalar(value, mark)
        if isinstance(node, yaml.SequenceNode):
            return YList([self.convert(item, depth + 1) for item in node.value], mark)
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
            self.refuse_surrogates(key, key_mark)
            if key in entries:
                self.problems.append(
                    Problem(
                        key_mark,
                        f"duplicate key {key!r} (first at line {key_marks[key].line})",
                        "keep only one",
                    )
                )
                continue
            entries[key] = self.convert(value_node, depth + 1)
            key_marks[key] = key_mark
        return YMap(entries, mark, key_marks)


_OS_HINTS = {
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.ENAMETOOLONG: "use a shorter file name",
    errno.ELOOP: "a symbolic link on the way points back to itself",
}


def resolved(path: Path) -> Path:
    """``path`` made absolute with links followed, or merely absolute when that is
    impossible (a link loop, a NUL in the name): reading it then says why, with its place."""
    try:
        return path.resolve()
    except (OSError, RuntimeError, ValueError):
        return path.absolute()


class _NotRegular(Exception):  # noqa: N818 - a refusal, reported as a problem
    def __init__(self, what: str) -> None:
        super().__init__(what)
        self.what = what


_KINDS = (
    (stat.S_ISDIR, "is a folder, not a file"),
    (stat.S_ISFIFO, "is not a regular file (a FIFO)"),
    (stat.S_ISCHR, "is not a regular file (a character device)"),
    (stat.S_ISBLK, "is not a regular file (a block device)"),
    (stat.S_ISSOCK, "is not a regular file (a socket)"),
)


def _read_at_most(path: Path, max_bytes: int) -> bytes:
    """At most ``max_bytes + 1`` bytes of a regular file (links followed).

    Opened without blocking, so a FIFO named as a tree can never hang the robot, and
    checked on the open file itself, so nothing can swap it between check and read;
    the size is what is read, never what ``stat`` claims (a /proc file says 0 bytes).
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise _NotRegular(
                next((what for test, what in _KINDS if test(mode)), "is not a regular file")
            )
        chunks: list[bytes] = []
        left = max_bytes + 1
        while left > 0:
            chunk = os.read(fd, min(left, 1 << 16))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def read_bytes(
    path: Path,
    shown: str | None = None,
    *,
    max_bytes: int = MAX_FILE_BYTES,
    kind: str = "vest YAML file",
    too_big_hint: str = "split it into subtrees",
) -> bytes:
    """The file's bytes, or a LoadError: missing, unreadable, too big, not a regular file
    (a folder, a FIFO, a device), or a path that names no file (a file as a folder, too
    long, a link loop, a NUL character). Every person's file is read here."""
    name = (shown or str(path)).replace("\0", "\\0")
    start = Mark(name, 1, 1)
    if "\0" in str(path):  # the OS cannot even be asked about such a name
        raise LoadError([Problem(start, "the file name contains a NUL character", "retype it")])
    try:
        data = _read_at_most(path, max_bytes)
    except _NotRegular as refused:
        hint = "name a .yaml file" if kind == "vest YAML file" else f"name a {kind}"
        folder = refused.what.startswith("is a folder")
        raise LoadError([Problem(start, refused.what, None if folder else hint)]) from None
    except FileNotFoundError:
        raise LoadError([Problem(start, "file not found", "check the path")]) from None
    except PermissionError:
        raise LoadError(
            [Problem(start, "permission denied", "check the file's permissions")]
        ) from None
    except IsADirectoryError:
        raise LoadError([Problem(start, "is a folder, not a file")]) from None
    except OSError as error:
        reason = os.strerror(error.errno) if error.errno else str(error)
        raise LoadError(
            [Problem(start, f"cannot read the file: {reason}", _OS_HINTS.get(error.errno or 0))]
        ) from None
    if len(data) > max_bytes:
        raise LoadError(
            [
                Problem(
                    start,
                    f"file is more than the {max_bytes // 1024} KiB a {kind} may be",
                    too_big_hint,
                )
            ]
        )
    return data


def read_text(
    path: Path,
    shown: str | None = None,
    *,
    max_bytes: int = MAX_FILE_BYTES,
    kind: str = "vest YAML file",
    too_big_hint: str = "split it into subtrees",
) -> str:
    """The file's text (see :func:`read_bytes`), or a LoadError, also when it is not UTF-8."""
    name = (shown or str(path)).replace("\0", "\\0")
    data = read_bytes(path, shown, max_bytes=max_bytes, kind=kind, too_big_hint=too_big_hint)
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
    """Parse one YAML document keeping places; None for an empty document.

    libyaml reads a good file fast (:mod:`engine.files.yaml_events`); a file it cannot
    read plainly is read again here, slowly and carefully, to word every problem.
    """
    try:
        return compose_fast(text, name, max_nodes=MAX_NODES, max_depth=MAX_DEPTH)
    except NeedsCarefulReading:
        pass
    composer: _Composer | None = None
    try:
        composer = _Composer(text)  # checks the characters first (ReaderError)
        node = composer.get_single_node()
    except _Refused as refused:
        raise LoadError(
            [Problem(_mark(name, refused.mark), refused.message, refused.hint)]
        ) from None
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = _mark(name, mark) if mark is not None else Mark(name, 1, 1)
        problem = error.problem or "cannot be read"
        slip = explain(text, where.line, problem, error.context)
        if slip is not None:
            where = Mark(name, slip.line, slip.column)
            raise LoadError([Problem(where, slip.message, slip.hint)]) from None
        message = f"YAML syntax error: {problem}"
        if error.context:
            message += f" ({error.context})"
        raise LoadError([Problem(where, message, hint_for(problem))]) from None
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
    except (ValueError, OverflowError, RecursionError) as error:
        # PyYAML's own slips: an escape like "\U0011FFFF" naming no character, ...
        where = _mark(name, composer.get_mark()) if composer else Mark(name, 1, 1)
        if "chr()" in str(error):
            message, hint = "an escape here names no character", "check \\U and \\x escapes"
        else:
            message, hint = f"YAML cannot read this: {error}", None
        raise LoadError([Problem(where, message, hint)]) from None
    finally:
        if composer is not None:
            composer.dispose()
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
