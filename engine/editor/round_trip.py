"""YAML read and written back as a person wrote it (ruamel.yaml's round trip): what the
editor changes is changed, the rest keeps its comments, key order, flow or block style,
quotes and indentation. Shared by the tree and dialog outlines."""

from __future__ import annotations

import io
import re
from typing import Any

import yaml
from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import YAMLError
from ruamel.yaml.scalarstring import DoubleQuotedScalarString, SingleQuotedScalarString

from engine.files.yaml_source import MAX_DEPTH

_FAST = hasattr(yaml, "CSafeLoader")
Style = tuple[int, int, int]
STYLES: tuple[Style, ...] = ((2, 4, 2), (2, 2, 2), (2, 2, 0), (4, 4, 2))
"""Indentation styles (mapping, sequence, dash offset) a file is tried against; the first
that reads and writes its text unchanged is the file's (vest's own files use the first)."""
PLAIN_WORD = re.compile(r"[A-Za-z_/#][A-Za-z0-9_./#-]*")
"""Text written without quotes: a word, a blackboard key, a colour (#FF5A8C)."""


class OutlineError(ValueError):
    """An outline or a file the editor cannot take, in words."""


def _yaml(style: Style = STYLES[0]) -> YAML:
    loader = YAML()  # round-trip: comments, order, flow style and quotes are kept
    loader.preserve_quotes = True
    loader.width = 4096  # a line the person wrote is never wrapped anew
    mapping, sequence, offset = style
    loader.indent(mapping=mapping, sequence=sequence, offset=offset)
    return loader


def read(text: str) -> tuple[Any, Style]:
    """``text`` as a round-trip document, and the indentation style it is written in;
    OutlineError when it is not YAML, or YAML the editor leaves to hand editing: anchors
    and aliases (``&x`` / ``*x``: one node in two places; an edit of one would change the
    other, and a few lines of them can stand for billions of nodes) or nesting deeper
    than vest's own files may be. Windows line ends are read as plain ones (written back
    with :func:`newline_of`'s)."""
    text = text.replace("\r\n", "\n")
    _plain_enough(text)
    try:
        document = _yaml().load(text)
    except YAMLError as error:
        raise OutlineError(f"not YAML the editor can read: {error}") from None
    style = next(
        (style for style in STYLES if dumped(_yaml(style).load(text), style) == text),
        STYLES[0],
    )
    return document, style


def _plain_enough(text: str) -> None:
    depth = 0
    try:
        for event in yaml.parse(text, Loader=yaml.CSafeLoader if _FAST else yaml.SafeLoader):
            if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None):
                raise OutlineError(
                    "the file uses YAML anchors (&name, *name): edit it by hand, or write "
                    "each node out where it is used"
                )
            if isinstance(event, yaml.CollectionStartEvent):
                depth += 1
                if depth > MAX_DEPTH:
                    raise OutlineError(f"nested more than {MAX_DEPTH} deep: edit it by hand")
            elif isinstance(event, yaml.CollectionEndEvent):
                depth -= 1
    except yaml.YAMLError as error:
        raise OutlineError(f"not YAML the editor can read: {error}") from None


def dumped(document: Any, style: Style, newline: str = "\n") -> str:
    """``document`` as text in ``style``, its lines ending in ``newline`` (the file's)."""
    out = io.StringIO()
    _yaml(style).dump(document, out)
    return out.getvalue().replace("\n", newline)


def newline_of(text: str) -> str:
    """How the file's lines end: Windows' ``\r\n`` when its first line does."""
    first = text.find("\n")
    return "\r\n" if first > 0 and text[first - 1] == "\r" else "\n"


def refilled(sequence: Any, items: list[Any]) -> CommentedSeq:
    """``sequence`` (its comments kept) holding ``items`` now."""
    kept = sequence if isinstance(sequence, CommentedSeq) else CommentedSeq()
    if list(kept) != items:
        kept[:] = items
    return kept


def update(mapping: CommentedMap, values: dict[str, Any], kept: tuple[str, ...]) -> None:
    """``mapping`` holding ``values``: changed values set, others removed (but the keys in
    ``kept``, which the caller handles), unchanged ones left as written (their quotes and
    comments)."""
    for key in list(mapping.keys()):
        if key not in values and key not in kept:
            del mapping[key]
    for key, value in values.items():
        if key in mapping and plain(mapping[key]) == value:
            continue
        mapping[key] = yaml_value(value)


def yaml_value(value: Any) -> Any:
    """A new value as YAML holds it; text other than one plain word (a pad, a key, a
    colour) in double quotes, as the therapist guide writes spoken text."""
    if isinstance(value, str) and not PLAIN_WORD.fullmatch(value):
        if '"' in value and "'" not in value:  # 'A "quoted" word', never \"
            return SingleQuotedScalarString(value)
        return DoubleQuotedScalarString(value)
    if isinstance(value, list):
        items = CommentedSeq(yaml_value(item) for item in value)
        items.fa.set_flow_style()
        return items
    if isinstance(value, dict):
        return CommentedMap((str(k), yaml_value(v)) for k, v in value.items())
    return value


def plain(value: Any) -> Any:
    """A round-trip value as plain JSON (its quotes and styles dropped)."""
    if isinstance(value, dict):
        return {str(key): plain(item) for key, item in value.items()}
    if isinstance(value, list):
        return [plain(item) for item in value]
    if isinstance(value, bool) or value is None:
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    return str(value)
