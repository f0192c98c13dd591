"""YAML read and written back as a person wrote it (ruamel.yaml's round trip): what the
editor changes is changed, the rest keeps its comments, key order, flow or block style,
quotes and indentation. Shared by the tree and dialog outlines."""

from __future__ import annotations

import io
import re
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import YAMLError
from ruamel.yaml.scalarstring import DoubleQuotedScalarString

Style = tuple[int, int, int]
STYLES: tuple[Style, ...] = ((2, 4, 2), (2, 2, 2), (2, 2, 0), (4, 4, 2))
"""Indentation styles (mapping, sequence, dash offset) a file is tried against; the first
that reads and writes its text unchanged is the file's (vest's own files use the first)."""
PLAIN_WORD = re.compile(r"[A-Za-z_/#][A-Za-z0-9_./#-]*")
"""Text written without quotes: a word, a blackboard key, a colour (#FF5A8C)."""


class OutlineError(ValueError):
    """An outline or a file the editor cannot take, in words."""


def _yaml(style: Style = STYLES[0]) -> YAML:
    yaml = YAML()  # round-trip: comments, order, flow style and quotes are kept
    yaml.preserve_quotes = True
    yaml.width = 4096  # a line the person wrote is never wrapped anew
    mapping, sequence, offset = style
    yaml.indent(mapping=mapping, sequence=sequence, offset=offset)
    return yaml


def read(text: str) -> tuple[Any, Style]:
    """``text`` as a round-trip document, and the indentation style it is written in;
    OutlineError when it is not YAML."""
    try:
        document = _yaml().load(text)
    except YAMLError as error:
        raise OutlineError(f"not YAML the editor can read: {error}") from None
    style = next(
        (style for style in STYLES if dumped(_yaml(style).load(text), style) == text),
        STYLES[0],
    )
    return document, style


def dumped(document: Any, style: Style) -> str:
    out = io.StringIO()
    _yaml(style).dump(document, out)
    return out.getvalue()


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
