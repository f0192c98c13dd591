"""Dialog rules and how a heard utterance is matched to one, on words, not characters.

A phrase matches an utterance only when every *meaning word* of the phrase is in it
(see :mod:`engine.dialogs.words`); a phrase made only of function words ("who are you")
matches only when all its words are there and nothing else meaningful is ("who are your
parents" is another question). The score is how much of the phrase was heard (function
words count less), lowered for each meaningful word the phrase does not explain. Below
``min_score``, or when two rules score too close to tell apart, nothing matches and the
robot says its fallback: a wrong answer is worse than none.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from engine.dialogs.words import (
    NUMBER_WORDS,
    PERSON_WORDS,
    QUESTION_WORDS,
    is_function_word,
    same_word,
    weight,
    words,
    written_as,
)
from engine.files.problems import Mark
from engine.values.templates import CompiledTemplate

EXTRA_WORD_FACTOR = 0.6
"""The score is multiplied by this for each meaning word (or question word) heard that the
phrase lacks: one is enough to refuse a phrase ("my dog *died*" is not "my dog", "I do *not*
like animals" is not "I like animals", "*what* pets do you like" is not "do you like pets").
List the longer ways of saying it as phrases of their own."""
AMBIGUITY_MARGIN = 0.1
"""Two rules scoring within this of each other cannot be told apart: neither matches.
Nor can two that both reach ``min_score`` ("what is your name and your favorite color")."""
DEFAULT_MIN_SCORE = 0.7
DEFAULT_LISTEN_S = 8.0


@dataclass(frozen=True)
class Phrase:
    """One phrase a rule listens for, as words with what the matcher needs to know."""

    text: str
    words: tuple[str, ...]
    required: frozenset[str]
    """Meaning, question and person words; every word when the phrase has no meaning word."""
    only_function_words: bool
    total_weight: float

    @classmethod
    def of(cls, text: str) -> Phrase:
        said = words(text)
        meaning = frozenset(w for w in said if not is_function_word(w))
        asks = frozenset(w for w in said if w in QUESTION_WORDS or w in PERSON_WORDS)
        return cls(
            text=text,
            words=said,
            required=(meaning | asks) if meaning else frozenset(said),
            only_function_words=not meaning,
            total_weight=sum(weight(w) for w in said),
        )

    def score(self, heard: Sequence[str]) -> float:
        """0..1: 0 when a required word is missing, or the phrase's numbers were not heard
        as they are, in their order ("four nine one three" is not "one nine three four";
        "sixty six" is not "six"); 1 for the phrase exactly."""
        if not self.words:
            return 0.0
        heard = written_as(heard, self.words)
        numbers = [w for w in self.words if w in NUMBER_WORDS]
        if numbers and [h for h in heard if h in NUMBER_WORDS] != numbers:
            return 0.0  # numbers are said in their order, and no other number is theirs
        found = [w for w in self.words if any(same_word(h, w) for h in heard)]
        if any(w not in found for w in self.required):
            return 0.0
        persons = {PERSON_WORDS[w] for w in self.words if w in PERSON_WORDS}
        extra = [
            h
            for h in heard
            if (
                not is_function_word(h)
                or h in QUESTION_WORDS
                or PERSON_WORDS.get(h, "") not in persons | {""}
            )
            and not any(same_word(h, w) for w in self.words)
        ]
        if extra and self.only_function_words:
            return 0.0
        covered = sum(weight(w) for w in dict.fromkeys(found)) / sum(
            weight(w) for w in dict.fromkeys(self.words)
        )
        return covered * EXTRA_WORD_FACTOR ** len(extra)


@dataclass(frozen=True)
class FollowUp:
    """What the robot listens for after a rule's answer asked a question.

    ``rules`` are tried first for the next utterance heard within ``listen_s`` seconds;
    when none matches, the dialog's own rules are; when those do not either, ``otherwise``
    is said (the dialog's fallback when there is none).
    """

    rules: tuple[DialogRule, ...]
    listen_s: float = DEFAULT_LISTEN_S
    otherwise: CompiledTemplate | None = None
    confirms: bool = False
    """The robot asked whether it heard a rule right (yes or no, at once)."""


@dataclass(frozen=True)
class DialogRule:
    """Hear one of ``phrases`` -> (optionally read ``read`` first) -> say ``answer``."""

    id: str
    phrases: tuple[Phrase, ...]
    answer: CompiledTemplate
    read: str | None = None
    follow_up: FollowUp | None = None
    mark: Mark | None = None
    """Where the rule is written."""
    confirm: CompiledTemplate | None = None
    """The question that asks whether the robot heard this rule right ("Did you ask what
    my name is?"), asked when what was heard is only like it
    (:mod:`engine.dialogs.confirming`); None: the robot never asks about it."""
    confirmed: FollowUp | None = None
    """What the robot listens for after asking ``confirm``: yes and no."""

    @property
    def line(self) -> int:
        return self.mark.line if self.mark is not None else 0

    def score(self, heard: Sequence[str]) -> tuple[float, Phrase | None]:
        """The best phrase's score, and that phrase."""
        best: tuple[float, Phrase | None] = (0.0, None)
        for phrase in self.phrases:
            score = phrase.score(heard)
            if score > best[0]:
                best = (score, phrase)
        return best


@dataclass(frozen=True)
class Match:
    rule: DialogRule
    score: float
    phrase: Phrase


@dataclass(frozen=True)
class Verdict:
    """What the matcher made of an utterance: the match, or why there is none."""

    match: Match | None
    reason: str
    candidates: tuple[Match, ...] = field(default=())
    """Every rule that scored above 0, best first."""


def judge(rules: Sequence[DialogRule], utterance: str, min_score: float) -> Verdict:
    """The rule ``utterance`` means, or why none: no rule's words, too low, or ambiguous.
    A phrase of one rule said word for word, in its order, is that rule's, whatever other
    rules it also fits ("one nine three four" is not "four nine one three")."""
    heard = words(utterance)
    if not heard:
        return Verdict(None, "nothing was heard")
    candidates: list[Match] = []
    for rule in rules:
        score, phrase = rule.score(heard)
        if phrase is not None and score > 0:
            candidates.append(Match(rule, score, phrase))
    candidates.sort(key=lambda m: -m.score)
    found = tuple(candidates)
    if not candidates:
        return Verdict(None, "no rule's meaning words were all heard", found)
    said = [m for m in candidates if m.phrase.words == written_as(heard, m.phrase.words)]
    if len({m.rule.id for m in said}) == 1:  # a phrase said word for word, in its order
        return Verdict(said[0], f"phrase {said[0].phrase.text!r}, word for word", found)
    best = candidates[0]
    if best.score < min_score:
        return Verdict(
            None, f"best rule {best.rule.id!r} scored {best.score:.2f} < {min_score:.2f}", found
        )
    runner_up = candidates[1].score if len(candidates) > 1 else 0.0
    if runner_up >= min_score or runner_up > best.score - AMBIGUITY_MARGIN:
        other = candidates[1]
        return Verdict(
            None,
            f"ambiguous: {best.rule.id!r} {best.score:.2f} and {other.rule.id!r} {other.score:.2f}",
            found,
        )
    return Verdict(best, f"phrase {best.phrase.text!r}", found)


@dataclass(frozen=True)
class Dialog:
    """A named set of rules with an optional fallback answer."""

    name: str
    rules: tuple[DialogRule, ...]
    fallback: CompiledTemplate | None = None
    min_score: float = DEFAULT_MIN_SCORE
    source: str = ""
    reprompts: tuple[CompiledTemplate, ...] = ()
    """Said in turn in place of the fallback when the robot again does not understand
    soon after a sorry (:func:`~engine.dialogs.confirming.reprompt`)."""

    def judge(self, utterance: str, follow_up: FollowUp | None = None) -> Verdict:
        """The matching rule, trying ``follow_up``'s rules first when the robot just asked."""
        if follow_up is not None:
            verdict = judge(follow_up.rules, utterance, self.min_score)
            if verdict.match is not None:
                return verdict
        return judge(self.rules, utterance, self.min_score)

    def match(self, utterance: str) -> Match | None:
        """The best rule for ``utterance``, or None when no rule clearly means it."""
        return self.judge(utterance).match

    def all_rules(self) -> list[DialogRule]:
        """Every rule, follow-ups included."""
        return [rule for rule, _ in self.rules_in_context()]

    def rules_in_context(self) -> list[tuple[DialogRule, FollowUp | None]]:
        """Every rule with the follow-up it is heard in (None: the dialog's own rules)."""
        found: list[tuple[DialogRule, FollowUp | None]] = []
        pending: list[tuple[DialogRule, FollowUp | None]] = [(r, None) for r in self.rules]
        while pending:
            rule, context = pending.pop(0)
            found.append((rule, context))
            if rule.follow_up is not None:
                pending.extend((r, rule.follow_up) for r in rule.follow_up.rules)
        return found

    @property
    def phrases(self) -> list[str]:
        """Every phrase the rules listen for, follow-ups and the answers to confirming
        questions included (the recognizer's vocabulary)."""
        rules = self.all_rules()
        rules += [r for rule in rules if rule.confirmed is not None for r in rule.confirmed.rules]
        return list(dict.fromkeys(phrase.text for rule in rules for phrase in rule.phrases))

    def templates(self) -> list[CompiledTemplate]:
        """Every answer the dialog may say: rules, follow-ups, fallbacks."""
        said: list[CompiledTemplate] = [rule.answer for rule in self.all_rules()]
        said += [
            r.follow_up.otherwise for r in self.all_rules() if r.follow_up and r.follow_up.otherwise
        ]
        said += [rule.confirm for rule in self.all_rules() if rule.confirm is not None]
        if self.fallback is not None:
            said.append(self.fallback)
        return [*said, *self.reprompts]
