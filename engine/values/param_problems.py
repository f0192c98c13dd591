"""How parameter checks report what is wrong, and what they may consult at load time.

A conversion problem raises :class:`ParamProblem` with a message that names the expected
type and the value found, and a hint where one helps; a problem across a node's parameters
is a :class:`ParamIssue`. The loader adds the place.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from engine.blackboard.catalogue import KeyCatalogue


class KnownDialogs(Protocol):
    """What a check may ask of the loaded dialogs: their names (the library answers it)."""

    @property
    def names(self) -> list[str]: ...

    def get(self, name: str) -> object | None: ...


class ParamProblem(Exception):  # noqa: N818 - a problem report, not a failure
    """A parameter value is wrong: ``message`` says what, ``hint`` how to fix it."""

    def __init__(self, message: str, hint: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.hint = hint


@dataclass(frozen=True)
class ParamIssue:
    """A problem across a node's parameters, found once they are all converted.

    ``param`` names the parameter whose value the loader points at (None: the node
    itself); ``message`` says what is wrong, ``hint`` how to fix it.
    """

    param: str | None
    message: str
    hint: str | None = None


@dataclass(frozen=True)
class CheckContext:
    """What parameter checks may consult at load time (never hardware)."""

    catalogue: KeyCatalogue
    dialogs: KnownDialogs | None = None


def shown(value: Any) -> str:
    """A YAML value as a message shows it: text quoted, containers by their kind."""
    if isinstance(value, str):
        return repr(value)
    if value is None:
        return "nothing"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return repr(value)


def did_you_mean(word: str, choices: Iterable[str]) -> str | None:
    """``"did you mean 'x'?"`` for the choice closest to ``word``, or None."""
    choices = list(choices)
    close = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    if not close:
        lowered = {c.lower(): c for c in choices}
        if word.lower() in lowered:
            close = [lowered[word.lower()]]
    return f"did you mean {close[0]!r}?" if close else None
