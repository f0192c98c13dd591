"""Checks across the rules of a dialog: what no single rule shows wrong.

- Rule ids are unique in a dialog, follow-ups included (``vest hear`` names rules by id).
- A phrase two rules of one conversation both listen for fits both whenever it is said,
  and two rules that fit cancel out: neither would ever answer it.
"""

from __future__ import annotations

from engine.dialogs.model import DialogRule
from engine.files.problems import Mark, Problems

__all__ = ["check_ids", "check_shared_phrases"]


def check_shared_phrases(rules: tuple[DialogRule, ...], problems: Problems) -> None:
    """A phrase two rules of one conversation both listen for fits both whenever it is
    said, and two rules that fit cancel out: neither would ever answer it."""
    holder: dict[tuple[str, ...], DialogRule] = {}
    for rule in rules:
        for phrase in rule.phrases:
            first = holder.setdefault(phrase.words, rule)
            if first is not rule:
                problems.add(
                    rule.mark or Mark("", 1, 1),
                    f"rules {first.id!r} (line {first.line}) and {rule.id!r} both listen for "
                    f"{phrase.text!r}: said, it fits both and neither answers",
                    "keep the phrase in one rule",
                )


def check_ids(rules: tuple[DialogRule, ...], problems: Problems) -> None:
    """Rule ids are unique in a dialog, follow-ups included (`vest hear` names rules by id)."""
    seen: dict[str, DialogRule] = {}
    pending = list(rules)
    while pending:
        rule = pending.pop(0)
        if rule.id in seen:
            problems.add(
                rule.mark or Mark("", 1, 1),
                f"two rules have the id {rule.id!r} (also line {seen[rule.id].line})",
                "give one of them another 'id:'",
            )
        seen.setdefault(rule.id, rule)
        if rule.follow_up is not None:
            pending.extend(rule.follow_up.rules)
