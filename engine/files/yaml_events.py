"""The fast way to read YAML with places: libyaml's events, composed here without recursion.

PyYAML's pure-Python scanner and composer make a 10,000-node tree take seconds to read.
libyaml (PyYAML's C parser, when installed) scans and parses; this module builds the
:class:`~engine.files.yaml_source.YMap` / ``YList`` / ``YScalar`` values straight from its
events with an explicit stack, so no file can exhaust Python's stack, and it stops reading
as soon as the nesting passes the limit (libyaml slows down quadratically on deep flow
nesting, so it is never asked to parse more than the limit).

It handles only files that are fine. For anything else (a syntax error, a refused tag,
a duplicate key, a nesting or size limit, an alias inside its own anchor, a character
libyaml refuses) it raises :class:`NeedsCarefulReading` and the careful, pure-Python
reader in :mod:`engine.files.yaml_source` reads the file again and words each problem
with its place: errors are rare, and their messages stay the same whichever reader runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import yaml

from engine.files.problems import Mark
from engine.files.yaml_values import LONE_SURROGATE, YList, YMap, YScalar, YValue, scalar_value

PARSER: type[Any] | None = getattr(yaml, "CSafeLoader", None)
"""libyaml's loader, or None where PyYAML was built without it."""

STANDARD_TAGS = frozenset(
    "tag:yaml.org,2002:" + name
    for name in ("str", "int", "float", "bool", "null", "map", "seq", "timestamp")
)


class NeedsCarefulReading(Exception):  # noqa: N818 - a hand-over, not a failure
    """The fast reader saw something it does not word: read the file the careful way."""


@dataclass
class _Open:
    """A sequence or mapping whose end event has not come yet."""

    mark: Mark
    anchor: str | None
    is_map: bool
    first_count: int
    items: list[Any] = field(default_factory=list)
    entries: dict[str, Any] = field(default_factory=dict)
    key_marks: dict[str, Mark] = field(default_factory=dict)
    key: str | None = None
    key_mark: Mark | None = None
    depth_below: int = 0


def compose_fast(text: str, file: str, *, max_nodes: int, max_depth: int) -> YValue | None:
    """The document's value with places (None when empty), or NeedsCarefulReading."""
    if PARSER is None:
        raise NeedsCarefulReading("no libyaml")
    parser = PARSER(text)
    constructor = yaml.SafeLoader("")
    anchors: dict[str, tuple[Any, int, int]] = {}  # anchor -> (value, values in it, depth)
    stack: list[_Open] = []
    count = 0
    document: YValue | None = None
    documents = 0
    try:
        while parser.check_event():
            event = parser.get_event()
            kind = type(event)
            if kind in (yaml.StreamStartEvent, yaml.StreamEndEvent, yaml.DocumentEndEvent):
                continue
            if kind is yaml.DocumentStartEvent:
                documents += 1
                if documents > 1:
                    raise NeedsCarefulReading("several documents")
                continue
            mark = Mark(file, event.start_mark.line + 1, event.start_mark.column + 1)
            if kind is yaml.AliasEvent:
                if event.anchor not in anchors:
                    raise NeedsCarefulReading("undefined or self-referring alias")
                value, size, depth = anchors[event.anchor]
                count += size
                if count > max_nodes or len(stack) + depth > max_depth:
                    raise NeedsCarefulReading("aliases expand past a limit")
                done, done_depth, raw_key = value, depth, None
            elif kind is yaml.ScalarEvent:
                count += 1
                tag = event.tag
                if tag is None or tag == "!":
                    tag = parser.resolve(yaml.ScalarNode, event.value, event.implicit)
                if tag not in STANDARD_TAGS or LONE_SURROGATE.search(event.value):
                    raise NeedsCarefulReading("a tag or a character to word")
                try:
                    value = scalar_value(constructor, tag, event.value, event.style)
                except (ValueError, OverflowError):
                    raise NeedsCarefulReading("a value to word") from None
                done = YScalar(value, mark)
                done_depth, raw_key = 1, event.value
                if event.anchor is not None:
                    anchors[event.anchor] = (done, 1, 1)
            elif kind in (yaml.SequenceStartEvent, yaml.MappingStartEvent):
                count += 1
                is_map = kind is yaml.MappingStartEvent
                if event.tag not in (None, "!") and event.tag not in STANDARD_TAGS:
                    raise NeedsCarefulReading("a refused tag")
                stack.append(_Open(mark, event.anchor, is_map, count))
                if len(stack) > max_depth or count > max_nodes:
                    raise NeedsCarefulReading("nested or sized past a limit")
                continue
            else:  # SequenceEndEvent or MappingEndEvent
                closed = stack.pop()
                done = (
                    YMap(closed.entries, closed.mark, closed.key_marks)
                    if closed.is_map
                    else YList(closed.items, closed.mark)
                )
                done_depth, raw_key = closed.depth_below + 1, None
                if closed.anchor is not None:
                    anchors[closed.anchor] = (done, count - closed.first_count + 1, done_depth)
            if count > max_nodes:
                raise NeedsCarefulReading("too many values")
            if not stack:
                document = done
                continue
            parent = stack[-1]
            parent.depth_below = max(parent.depth_below, done_depth)
            if not parent.is_map:
                parent.items.append(done)
            elif parent.key_mark is None:
                if raw_key is None or raw_key == "<<" or raw_key in parent.entries:
                    raise NeedsCarefulReading("a key to word")
                parent.key, parent.key_mark = raw_key, mark
            else:
                assert parent.key is not None
                parent.entries[parent.key] = done
                parent.key_marks[parent.key] = parent.key_mark
                parent.key, parent.key_mark = None, None
    except yaml.YAMLError as error:
        raise NeedsCarefulReading(str(error)) from None
    finally:
        parser.dispose()
        constructor.dispose()
    return document
