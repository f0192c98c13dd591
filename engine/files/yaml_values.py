"""YAML values that remember where they were written: what every loader checks.

A :class:`YMap`, :class:`YList` or :class:`YScalar` keeps the :class:`Mark` of its value
(and a mapping the mark of each key), so a loader can name the place of any problem.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import yaml

from engine.files.problems import Mark

LONE_SURROGATE = re.compile("[\ud800-\udfff]")
"""Half of a UTF-16 pair written alone ("\\uD800"): no character, and no output can show it."""


@dataclass
class YScalar:
    """One value and its place; ``via`` names the ``${parameter}`` it was written through
    and where that parameter's value was set (a tree's ``params:`` or a profile)."""

    value: Any
    mark: Mark
    via: tuple[str, Mark] | None = None


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


def scalar_value(constructor: yaml.SafeLoader, tag: str, text: str, style: str | None) -> Any:
    """The Python value of a scalar with a standard ``tag``; dates stay text (2024-13-45 is
    no date). Raises ValueError/OverflowError (e.g. an integer of too many digits)."""
    if tag.endswith(":timestamp") or tag.endswith(":str"):
        return text
    node = yaml.ScalarNode(tag, text, style=style)
    return constructor.construct_object(node, deep=True)
