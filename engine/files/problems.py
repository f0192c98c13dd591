"""Problems found in a person's file, each with its place and a hint."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from engine.errors import ConfigError
from engine.values.param_problems import did_you_mean


@dataclass(frozen=True, order=True)
class Mark:
    """A place in a file: 1-based line and column."""

    file: str
    line: int
    column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


@dataclass(frozen=True)
class Problem:
    """One thing wrong, where, and how to fix it."""

    mark: Mark
    message: str
    hint: str | None = None

    def __str__(self) -> str:
        hint = f" ({self.hint})" if self.hint else ""
        return f"{self.mark}: {self.message}{hint}"


class Problems:
    """Collects problems while a file is checked; raise them all at once at the end."""

    def __init__(self) -> None:
        self.items: list[Problem] = []

    def add(self, mark: Mark, message: str, hint: str | None = None) -> None:
        self.items.append(Problem(mark, message, hint))

    def unknown_fields(
        self,
        key_marks: Mapping[str, Mark],
        known: Sequence[str],
        what: str = "",
        *,
        message: str = "unknown {what}field {key!r}",
    ) -> bool:
        """Report each key of a mapping that is not one of ``known`` fields; True if none.

        ``key_marks`` is a YAML mapping's keys with their places; ``what`` names the
        mapping in the message ("unknown dialog field 'sya'"), or ``message`` words it
        (``{key!r}`` is the unknown key). The hint is the nearest known field, or all.
        """
        clean = True
        for key, mark in key_marks.items():
            if key not in known:
                clean = False
                words = message.format(what=what + " " if what else "", key=key)
                self.add(mark, words, did_you_mean(key, known) or "fields: " + ", ".join(known))
        return clean

    def extend(self, other: Problems | list[Problem]) -> None:
        self.items.extend(other.items if isinstance(other, Problems) else other)

    def __bool__(self) -> bool:
        return bool(self.items)

    def __len__(self) -> int:
        return len(self.items)

    def raise_if_any(self) -> None:
        if self.items:
            raise LoadError(self.items)


class LoadError(ConfigError):
    """A file (or several) could not be loaded; ``problems`` lists every reason."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = sorted(dict.fromkeys(problems), key=lambda p: (p.mark, p.message))
        super().__init__("\n".join(str(p) for p in self.problems))
