"""A dialog file as the editor sees it (its questions and answers), and back to YAML that
keeps what was not changed, as :mod:`engine.editor.tree_yaml` does for trees.

The outline: ``{"dialog", "fallback", "rules"}``, each rule ``{"id", "rule", "hear",
"say", "more"}``: ``id`` where it stood in the file (``rules/2``; none for a rule the page
added), ``rule`` its name in the file, ``hear`` the phrases a person may say, ``say`` the
answer, ``more`` True when the rule holds more than the editor shows (a follow-up
question, a sensor read into the answer): those parts stay as written.
"""

from __future__ import annotations

from typing import Any

from ruamel.yaml.comments import CommentedMap, CommentedSeq

from engine.editor.round_trip import (
    OutlineError,
    dumped,
    newline_of,
    plain,
    read,
    refilled,
    yaml_value,
)

SHOWN = ("id", "hear", "say")
"""The keys of a rule the editor shows; a rule's others are kept as written."""


class DialogText:
    """One dialog file's text, read for editing."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.document, self.style = read(text)
        self.newline = newline_of(text)
        if not isinstance(self.document, CommentedMap) or "rules" not in self.document:
            raise OutlineError("not a dialog file (a dialog has 'rules:')")
        if not isinstance(self.document["rules"], CommentedSeq):
            raise OutlineError("the dialog's 'rules:' is not a list")

    def outline(self) -> dict[str, Any]:
        rules = []
        for index, raw in enumerate(self.document["rules"]):
            if not isinstance(raw, CommentedMap):
                raise OutlineError(f"rule {index + 1} is not a mapping")
            rules.append(
                {
                    "id": f"rules/{index}",
                    "rule": plain(raw.get("id")),
                    "hear": plain(raw.get("hear")) or [],
                    "say": plain(raw.get("say")),
                    "more": any(key not in SHOWN for key in raw),
                }
            )
        return {
            "dialog": plain(self.document.get("dialog")),
            "fallback": plain(self.document.get("fallback")),
            "rules": rules,
        }

    def written(self, outline: dict[str, Any]) -> str:
        """The file's text with ``outline``'s changes made; its own text when none."""
        if outline == self.outline():
            return self.text
        rules = outline.get("rules")
        if not isinstance(rules, list):
            raise OutlineError("rules: a list of questions and answers")
        document = read(self.text)[0]  # a fresh copy: this one stays as read
        originals = {f"rules/{i}": raw for i, raw in enumerate(document["rules"])}
        built = [self._rule(rule, originals, i) for i, rule in enumerate(rules)]
        document["rules"] = refilled(document["rules"], built)
        fallback = outline.get("fallback")
        if fallback != plain(document.get("fallback")):
            if fallback:
                document["fallback"] = yaml_value(str(fallback))
            else:
                document.pop("fallback", None)
        return dumped(document, self.style, self.newline)

    @staticmethod
    def _rule(rule: Any, originals: dict[str, CommentedMap], index: int) -> CommentedMap:
        if not isinstance(rule, dict):
            raise OutlineError(f"rule {index + 1}: a mapping with hear and say")
        raw = originals.pop(str(rule.get("id")), None)  # once: a second use is a new rule
        mapping = raw if raw is not None else CommentedMap()
        hear = rule.get("hear")
        if not isinstance(hear, list) or not all(isinstance(p, str) for p in hear):
            raise OutlineError(f"rule {index + 1}: hear is a list of phrases")
        for key, value in (("id", rule.get("rule")), ("hear", hear), ("say", rule.get("say"))):
            if value in (None, "", []):
                mapping.pop(key, None)
            elif plain(mapping.get(key)) != value:
                mapping[key] = yaml_value(value)
        return mapping
