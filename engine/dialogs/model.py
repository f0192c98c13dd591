"""Dialog rules and how a heard utterance is matched to one.

Matching normalizes both sides (case, punctuation, contractions; in any script) and
tolerates small recognition errors: an exact phrase scores 1.0, a phrase inside a longer
utterance 0.95, otherwise the similarity of the two texts, accepted from ``min_score``.
"""

from __future__ import annotations

import difflib
import re
import unicodedata
from dataclasses import dataclass

from engine.values.templates import CompiledTemplate

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
_SPACES = re.compile(r"\s+")
_WORD_CATEGORIES = ("L", "M", "N")
"""Letters, marks and digits of any script (marks: the vowel signs of Devanagari, accents)."""


def _word_character(char: str) -> bool:
    return char == "'" or unicodedata.category(char)[0] in _WORD_CATEGORIES


def normalize(text: str) -> str:
    """Case folded, no punctuation, contractions spelled out, single spaces; in any script.

    Accents are kept (``café`` stays ``café``); both sides of a match are normalized the
    same way (Unicode NFKC), so a composed and a decomposed ``é`` are the same letter.
    """
    folded = unicodedata.normalize("NFKC", text).casefold().replace("\u2019", "'")
    words = "".join(c if _word_character(c) else " " for c in folded).split()
    expanded = " ".join(_CONTRACTIONS.get(word, word) for word in words)
    return _SPACES.sub(" ", expanded.replace("'", "")).strip()


@dataclass(frozen=True)
class DialogRule:
    """Hear one of ``phrases`` -> (optionally read ``read`` first) -> say ``answer``."""

    phrases: tuple[str, ...]
    answer: CompiledTemplate
    read: str | None = None
    line: int = 0

    def literal_score(self, heard: str) -> float:
        """1.0 for an exact phrase, 0.95 for a phrase inside the utterance, else 0."""
        best = 0.0
        padded = f" {heard} "
        for phrase in self.phrases:
            if heard == phrase:
                return 1.0
            if f" {phrase} " in padded:
                best = 0.95
        return best

    def fuzzy_score(self, heard: str, at_least: float) -> float:
        """The best similarity of ``heard`` to a phrase, skipping phrases that cannot beat
        ``at_least`` (cheap upper bounds first: difflib is the costly part of matching)."""
        best = 0.0
        matcher = difflib.SequenceMatcher(None, heard)
        for phrase in self.phrases:
            matcher.set_seq2(phrase)
            if matcher.real_quick_ratio() < at_least or matcher.quick_ratio() < at_least:
                continue
            ratio = matcher.ratio()
            if ratio >= at_least:
                best, at_least = max(best, ratio), max(at_least, ratio)
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
        for rule in self.rules:  # exact and contained phrases win before any fuzzy match
            score = rule.literal_score(heard)
            if score > 0 and (best is None or score > best.score):
                best = Match(rule, score)
        if best is not None:
            return best
        for rule in self.rules:
            floor = best.score if best is not None else self.min_score
            score = rule.fuzzy_score(heard, floor)
            if score >= floor and (best is None or score > best.score):
                best = Match(rule, score)
        return best

    @property
    def phrases(self) -> list[str]:
        """Every phrase the rules listen for (for the speech recognizer's vocabulary)."""
        return [phrase for rule in self.rules for phrase in rule.phrases]
