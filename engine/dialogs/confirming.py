"""Asking instead of giving up: a rule's question to confirm it, and reprompts after a sorry.

A rule may say how the robot asks whether it heard it right::

    - id: name
      hear: ["what is your name"]
      say: "My name is H B S 2"
      confirm: "Did you ask what my name is?"

When what was heard matches no rule but is like one of the phrases of a rule with
``confirm:`` (:func:`maybe_meant`: "what is your aim" for "what is your name", a child's
"can you play again" for "can we play a game"), the robot asks that question instead of
saying sorry, and listens for the answer as for a follow-up (:func:`confirmation`): yes
(or the dialog's own ``~yes`` words) is answered as the rule would have been, no with the
dialog's first reprompt (or its fallback), and anything else is heard afresh. The robot
never answers a rule it was not sure of without a yes.

A dialog may list ``reprompt:`` lines, said in turn in place of the fallback when the robot
again does not understand soon after a sorry (:data:`REPROMPT_WITHIN_S`): "Sorry, I did not
understand." then "Can you say it again, a little slower?" then "You can ask me my name".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from engine.dialogs.model import DEFAULT_LISTEN_S, Dialog, DialogRule, FollowUp, Phrase
from engine.dialogs.words import alike
from engine.files.problems import Mark, Problems
from engine.values.templates import CompiledTemplate

YES = ("yes", "yeah", "yep", "yes please", "sure", "right", "that is right", "i did", "yes i did")
"""What answers yes to a confirming question, when the dialog has no ``~yes`` concept."""
NO = ("no", "nope", "no i did not", "i did not", "not really", "that is wrong")
"""What answers no, when the dialog has no ``~no`` concept."""
MAYBE_ALIKE = 0.6
"""What was heard is like a phrase when it is at least this alike (0..1,
:func:`~engine.dialogs.words.alike`): "can you play again" and "can we play a game" are
0.72, "what is your name" and "what is the time" 0.58."""
MAYBE_MARGIN = 0.1
"""The rule asked about must be this much more alike than any other rule: between two alike
ones the robot cannot tell which to ask about."""
REPROMPT_WITHIN_S = 60.0
"""A sorry this soon (seconds) after the last one is said in other words, the next reprompt."""
IN_PARTS_WITHIN_S = 5.0
"""An utterance heard this soon (seconds) after one that was not understood may be the rest
of its sentence (a child pauses mid-sentence): when it is not understood alone, the two are
judged as one."""
IN_PARTS_WORDS = 16
"""At most this many of the words not understood so far are kept to join to the next."""


def confirmation(
    rule: DialogRule,
    no_answer: CompiledTemplate,
    yes: Sequence[str] = YES,
    no: Sequence[str] = NO,
) -> FollowUp:
    """What the robot listens for after asking whether it heard ``rule``: yes, answered as
    ``rule`` (its reading and its own follow-up included), or no, answered ``no_answer``."""
    agreed = DialogRule(
        id=f"{rule.id}/yes",
        phrases=tuple(Phrase.of(text) for text in dict.fromkeys(yes)),
        answer=rule.answer,
        read=rule.read,
        follow_up=rule.follow_up,
        mark=rule.mark,
    )
    refused = DialogRule(
        id=f"{rule.id}/no",
        phrases=tuple(Phrase.of(text) for text in dict.fromkeys(no)),
        answer=no_answer,
        mark=rule.mark,
    )
    listen_s = rule.follow_up.listen_s if rule.follow_up is not None else DEFAULT_LISTEN_S
    return FollowUp((agreed, refused), listen_s, confirms=True)


def with_confirmations(
    rules: tuple[DialogRule, ...],
    no_answer: CompiledTemplate | None,
    concepts: dict[str, list[str]],
    problems: Problems,
) -> tuple[DialogRule, ...]:
    """``rules`` (and their follow-ups' rules) with what each ``confirm:`` question listens
    for: the dialog's ``~yes`` and ``~no`` concepts where it has them, else :data:`YES` and
    :data:`NO`; ``no_answer`` is said to a no. A rule that confirms in a dialog with nothing
    to say to a no (no ``reprompt:``, no ``fallback:``) is a problem."""
    yes, no = concepts.get("yes", YES), concepts.get("no", NO)
    yes = [word for word in yes if word.strip()] or list(YES)
    no = [word for word in no if word.strip()] or list(NO)
    done: list[DialogRule] = []
    for rule in rules:
        follow_up = rule.follow_up
        if follow_up is not None:
            inner = with_confirmations(follow_up.rules, no_answer, concepts, problems)
            follow_up = replace(follow_up, rules=inner)
        confirmed = None
        if rule.confirm is not None:
            if no_answer is None:
                where = rule.mark or Mark("dialog", 1, 1)
                problems.add(
                    where,
                    f"rule {rule.id!r} asks to confirm, but the dialog says nothing to a no",
                    "add 'fallback:' or 'reprompt:' to the dialog",
                )
            else:
                confirmed = confirmation(replace(rule, follow_up=follow_up), no_answer, yes, no)
        done.append(replace(rule, follow_up=follow_up, confirmed=confirmed))
    return tuple(done)


def maybe_meant(dialog: Dialog, heard: str, asked: FollowUp | None = None) -> DialogRule | None:
    """The rule with a ``confirm:`` question that ``heard`` (which matched none) is like
    enough to ask about (:data:`MAYBE_ALIKE`, :data:`MAYBE_MARGIN`), the follow-up's
    rules first when the robot just asked (``asked``); None when none is, or when the robot
    has just asked about that very rule (its answer is neither yes nor no: it is not asked
    again, the robot says sorry)."""
    for rules in ([*asked.rules] if asked is not None else [], [*dialog.rules]):
        likeness = sorted(
            (
                (max((alike(p.text, heard) for p in rule.phrases), default=0.0), index)
                for index, rule in enumerate(rules)
            ),
            reverse=True,
        )
        if not likeness:
            continue
        best, index = likeness[0]
        runner_up = likeness[1][0] if len(likeness) > 1 else 0.0
        rule = rules[index]
        if best >= MAYBE_ALIKE and best - runner_up >= MAYBE_MARGIN and rule.confirm is not None:
            just_asked = asked is not None and asked is rule.confirmed
            return None if just_asked else rule  # asked once, a sorry follows
    return None


def reprompt(dialog: Dialog, misses: int) -> tuple[CompiledTemplate | None, int]:
    """What the robot says the ``misses``-th time in a row it does not understand, and
    which reprompt that is (1 for the first; 0 for the fallback): the fallback first, then
    each reprompt in turn, round again after the last; None when the dialog has neither."""
    lines = dialog.reprompts
    if dialog.fallback is not None and (misses <= 1 or not lines):
        return dialog.fallback, 0
    if not lines:
        return None, 0
    turn = (misses - (2 if dialog.fallback is not None else 1)) % len(lines)
    return lines[turn], turn + 1
