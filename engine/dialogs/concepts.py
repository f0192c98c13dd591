"""A dialog's concepts: named lists of synonyms, written ``~name`` in a phrase, and the
phrases they expand to (with limits: a few lines must never expand to millions)."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from engine.dialogs.words import normalize
from engine.files.problems import Problems
from engine.files.yaml_source import YList, YMap, YScalar, YValue
from engine.values.param_problems import did_you_mean

MAX_PHRASE_EXPANSIONS = 200
"""How many phrases one ``hear:`` phrase may expand to through its ``~concepts``."""
MAX_DIALOG_EXPANSIONS = 2000
"""How many phrases all of a dialog's ``hear:`` phrases may expand to together."""


def read_concepts(value: YValue | None, problems: Problems) -> dict[str, list[str]]:
    concepts: dict[str, list[str]] = {}
    if value is None:
        return concepts
    if not isinstance(value, YMap):
        problems.add(value.mark, "'concepts' must map names to lists of words")
        return concepts
    for name, words in value.items():
        if not isinstance(words, YList) or not all(isinstance(w, YScalar) for w in words):
            problems.add(words.mark, f"concept {name!r} must be a list of words or phrases")
            continue
        concepts[name] = [normalize(str(w.value)) for w in words if isinstance(w, YScalar)]
    return concepts


def expand(phrase: str, concepts: dict[str, list[str]]) -> list[str] | tuple[str, str | None]:
    """Every phrase ``~concept`` words expand to, or (message, hint) saying what is wrong."""
    options: list[list[str]] = []
    for word in phrase.split():
        if word.startswith("~"):
            synonyms = concepts.get(word[1:])
            if synonyms is None:
                hint = did_you_mean(word[1:], list(concepts))
                return f"unknown concept {word!r}" + (f"; {hint}" if hint else ""), None
            options.append(synonyms)
        else:
            options.append([normalize(word)])
    count = math.prod(len(choices) for choices in options)
    if count > MAX_PHRASE_EXPANSIONS:  # counted before expanding: 40^5 phrases would hang
        return (
            f"phrase expands to {count} phrases, more than {MAX_PHRASE_EXPANSIONS}",
            "use fewer ~concepts in one phrase, or write several shorter phrases",
        )
    expanded = [" ".join(filter(None, combo)) for combo in itertools.product(*options)]
    if not any(expanded):
        return f"phrase {phrase!r} has no words", "write it with letters or digits"
    return expanded


@dataclass
class Budget:
    """How many phrases a dialog's concepts may still expand to (-1: gone over)."""

    left: int = MAX_DIALOG_EXPANSIONS
