"""Dialog rules and how a heard utterance is matched to one.

Matching normalizes both sides (case, punctuation, contractions) and tolerates small
recognition errors: an exact phrase scores 1.0, a phrase inside a longer utterance 0.95,
otherwise the similarity of the two texts, accepted from ``min_score``.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass

from engine.nodes.templates import CompiledTemplate

_CONTRACTIONS = {
    "what's": "what is",
    "who's": "who is",
    "it's": "it is",
    "how's": "how is",
    "i'm": "i am",
    "you're": "you are",
    "what're": "what are",
    "favourite": "favorite",
    "colour": "color",
}
_NOT_WORD = re.compile(r"[^a-z0-9' ]+")
_SPACES = re.compile(r"\s+")


def normalize(text: str) -> str:
    """Lower case, no punctuation, contractions spelled out, single spaces."""
    words = _NOT_WORD.sub(" ", text.lower().replace("\u2019", "'")).split()
    expanded = " ".join(_CONTRACTIONS.get(word, word) for word in words)
    return _SPACES.sub(" ", expanded.replace("'", "")).strip()


@dataclass(frozen=True)
class DialogRule:
    """Hear one of ``phrases`` -> (optionally read ``read`` first) -> say ``answer``."""

    phrases: tuple[str, ...]
    answer: CompiledTemplate
    read: str | None = None
    line: int = 0

    def score(self, heard: str) -> float:
        best = 0.0
        for phrase in self.phrases:
            if heard == phrase:
                return 1.0
            if f" {phrase} " in f" {heard} ":
                best = max(best, 0.95)
            else:
                best = max(best, difflib.SequenceMatcher(None, heard, phrase).ratio())
        return best


@dataclass(frozen=True)
class Match:
    rule: DialogRule
    score: float


@dataclass(frozen=True)
class Dialog:
    """A named set of rules with an optional fallback answer."""

    name: str
    rules: tuple[DialogRule, ...]
    fallback: CompiledTemplate | None = None
    min_score: float = 0.8
    source: str = ""

    def match(self, utterance: str) -> Match | None:
        """The best rule for ``utterance``, or None when none scores ``min_score``."""
        heard = normalize(utterance)
        if not heard:
            return None
        best: Match | None = None
        for rule in self.rules:
            score = rule.score(heard)
            if score >= self.min_score and (best is None or score > best.score):
                best = Match(rule, score)
        return best

    @property
    def phrases(self) -> list[str]:
        """Every phrase the rules listen for (for the speech recognizer's vocabulary)."""
        return [phrase for rule in self.rules for phrase in rule.phrases]
