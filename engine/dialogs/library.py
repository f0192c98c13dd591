"""Loading dialog files from a folder, with file:line:column problems.

A dialog file::

    dialog: default
    concepts:                       # named lists of synonyms, used as ~name in phrases
      greeting: [hello, hi, hey]
    rules:
      - hear: ["what is your name", "who are you"]
        say: "My name is H B S 2"
      - hear: ["what is the temperature"]
        read: temperature           # read this sensor before answering
        say: "The temperature is {temperature_f:.0f} degrees"
      - hear: ["~greeting robot"]
        say: "Hello!"
      - id: pets                    # a name for the rule (default: its first phrase)
        hear: ["do you like animals"]
        say: "I love animals. Do you have a pet?"
        then:                       # a follow-up: what the robot listens for next
          listen_s: 10              # for this long (default 8)
          rules:
            - hear: ["yes", "i do"]
              say: "Lovely!"
          otherwise: "I see."       # said when the answer matches no rule
    fallback: "Sorry, I did not catch that."
    min_score: 0.7                  # how sure the matcher must be (0..1)
"""

from __future__ import annotations

from pathlib import Path

from engine.blackboard.catalogue import KeyCatalogue
from engine.dialogs.concepts import MAX_DIALOG_EXPANSIONS, Budget, expand, read_concepts
from engine.dialogs.confirming import with_confirmations
from engine.dialogs.model import (
    DEFAULT_LISTEN_S,
    DEFAULT_MIN_SCORE,
    Dialog,
    DialogRule,
    FollowUp,
    Phrase,
)
from engine.dialogs.rule_checks import check_ids, check_shared_phrases
from engine.files.problems import LoadError, Mark, Problems
from engine.files.yaml_source import (
    YList,
    YMap,
    YScalar,
    YValue,
    describe,
    load_yaml,
    resolved,
)
from engine.services.interfaces import ON_REQUEST_SENSORS
from engine.values.param_problems import CheckContext, ParamProblem, did_you_mean
from engine.values.templates import CompiledTemplate, compile_template

_TOP_KEYS = ("dialog", "description", "concepts", "rules", "fallback", "reprompt", "min_score")
_RULE_KEYS = ("id", "hear", "say", "read", "then", "confirm")
_FOLLOW_UP_KEYS = ("rules", "listen_s", "otherwise")
MAX_FOLLOW_UP_DEPTH = 5


def find_dialogs_folder(path: Path) -> Path | None:
    """The nearest ``dialogs/`` folder beside ``path`` or above it, named as ``path`` is
    (relative for a relative path, so problems show ``dialogs/x.yaml`` as a person wrote it)
    until the path runs out of parents, absolute above that."""
    for folder in [*path.parents, *resolved(path).parents]:
        candidate = folder / "dialogs"
        if candidate.is_dir():
            return candidate
    return None


OUTSIDE = "outside the folder the editor works in: not read"
"""The problem of a file that leads out of the folder being edited (``vest edit``)."""


class DialogLibrary:
    """Dialogs by name, loaded from ``*.yaml`` files in a folder."""

    def __init__(self, dialogs: dict[str, Dialog] | None = None) -> None:
        self.dialogs = dialogs or {}

    @classmethod
    def from_folder(
        cls, folder: Path, catalogue: KeyCatalogue, *, inside: Path | None = None
    ) -> DialogLibrary:
        """Every dialog in ``folder``; LoadError listing all problems of all files. With
        ``inside``, a file that leads out of that folder (a link) is a problem, never read."""
        problems = Problems()
        dialogs: dict[str, Dialog] = {}
        for path in sorted(folder.glob("*.yaml")):
            if inside is not None and not resolved(path).is_relative_to(resolved(inside)):
                problems.add(Mark(str(path), 1, 1), OUTSIDE, "keep dialogs inside it")
                continue
            try:
                dialog = load_dialog(path, catalogue)
            except LoadError as error:
                problems.extend(error.problems)
                continue
            holder = dialogs.get(dialog.name)
            if holder is not None:
                problems.add(
                    Mark(str(path), 1, 1),
                    f"two dialogs are named {dialog.name!r} (also {holder.source})",
                    "rename one: trees name a dialog by its name",
                )
                continue
            dialogs[dialog.name] = dialog
        problems.raise_if_any()
        return cls(dialogs)

    def get(self, name: str) -> Dialog | None:
        return self.dialogs.get(name)

    @property
    def names(self) -> list[str]:
        return sorted(self.dialogs)

    def phrases(self) -> list[str]:
        return sorted({p for dialog in self.dialogs.values() for p in dialog.phrases})


def load_dialog(path: Path, catalogue: KeyCatalogue, shown: str | None = None) -> Dialog:
    name = shown or str(path)
    document = load_yaml(path, name)
    return check_dialog(document, name, catalogue, default_name=path.stem)


def check_dialog(
    document: YValue | None, file: str, catalogue: KeyCatalogue, *, default_name: str
) -> Dialog:
    """Validate a parsed dialog file whole; LoadError with every problem."""
    from engine.files.problems import Mark

    problems = Problems()
    if not isinstance(document, YMap):
        where = document.mark if document is not None else Mark(file, 1, 1)
        problems.add(where, "a dialog file is a mapping with 'dialog:' and 'rules:'")
        problems.raise_if_any()
    assert isinstance(document, YMap)
    problems.unknown_fields(document.key_marks, _TOP_KEYS, "dialog")
    ctx = CheckContext(catalogue)
    dialog_name = _text(document.get("dialog"), problems, "dialog") or default_name
    concepts = read_concepts(document.get("concepts"), problems)
    budget = Budget()
    rules = _rules(document.get("rules"), document.mark, concepts, ctx, problems, budget, 0)
    check_ids(rules, problems)
    fallback = None
    raw_fallback = document.get("fallback")
    if raw_fallback is not None:
        fallback = _template(raw_fallback, ctx, problems)
    reprompts = _reprompts(document.get("reprompt"), ctx, problems)
    min_score = DEFAULT_MIN_SCORE
    raw_score = document.get("min_score")
    if raw_score is not None:
        min_score = _number(raw_score, problems, "min_score", 0.0, 1.0, DEFAULT_MIN_SCORE)
    no_answer = reprompts[0] if reprompts else fallback
    rules = with_confirmations(rules, no_answer, concepts, problems)
    problems.raise_if_any()
    return Dialog(dialog_name, rules, fallback, min_score, file, reprompts)


def _reprompts(
    value: YValue | None, ctx: CheckContext, problems: Problems
) -> tuple[CompiledTemplate, ...]:
    """``reprompt:``: one line or a list of them."""
    if value is None:
        return ()
    items = value.items if isinstance(value, YList) else [value]
    if not items:
        problems.add(value.mark, "'reprompt' is empty", "list what the robot says instead")
    said = (_template(item, ctx, problems, "a 'reprompt' line") for item in items)
    return tuple(template for template in said if template is not None)


def _text(value: YValue | None, problems: Problems, what: str) -> str | None:
    if value is None:
        return None
    if not isinstance(value, YScalar) or not isinstance(value.value, str | int | float):
        problems.add(value.mark, f"{what!r} must be text, got {describe(value)}")
        return None
    return str(value.value)


def _rules(
    raw_rules: YValue | None,
    where: Mark,
    concepts: dict[str, list[str]],
    ctx: CheckContext,
    problems: Problems,
    budget: Budget,
    depth: int,
    parent: str = "",
) -> tuple[DialogRule, ...]:
    if raw_rules is None:
        problems.add(where, "a dialog needs 'rules:'", "add a list of hear/say rules")
        return ()
    if not isinstance(raw_rules, YList):
        problems.add(raw_rules.mark, f"'rules' must be a list, got {describe(raw_rules)}")
        return ()
    if not raw_rules.items:
        problems.add(raw_rules.mark, "'rules' is empty", "add a hear/say rule")
        return ()
    rules = (_rule(raw, concepts, ctx, problems, budget, depth, parent) for raw in raw_rules)
    kept = tuple(rule for rule in rules if rule is not None)
    check_shared_phrases(kept, problems)
    return kept


def _number(
    raw: YValue,
    problems: Problems,
    what: str,
    low: float,
    high: float,
    default: float,
    from_low: bool = False,
) -> float:
    """A number in (low, high], or [low, high] with ``from_low``; else a problem."""
    value = raw.value if isinstance(raw, YScalar) else None
    if isinstance(value, bool) or not isinstance(value, int | float):
        value = float("nan")  # refused below, as every comparison with NaN fails
    if not (low <= value if from_low else low < value) or not value <= high:
        lowest = f"at least {low:g}" if from_low else f"above {low:g}"
        problems.add(
            raw.mark,
            f"{what!r} must be a number {lowest} and at most {high:g}, got {describe(raw)}",
        )
        return default
    return float(value)


def _follow_up(
    raw: YValue,
    concepts: dict[str, list[str]],
    ctx: CheckContext,
    problems: Problems,
    budget: Budget,
    depth: int,
    parent: str,
) -> FollowUp | None:
    if not isinstance(raw, YMap):
        problems.add(raw.mark, "'then' is a mapping with 'rules:' (and 'listen_s', 'otherwise')")
        return None
    if depth >= MAX_FOLLOW_UP_DEPTH:
        problems.add(
            raw.mark,
            f"follow-ups nest deeper than {MAX_FOLLOW_UP_DEPTH}",
            "flatten the conversation",
        )
        return None
    problems.unknown_fields(raw.key_marks, _FOLLOW_UP_KEYS, "follow-up")
    rules = _rules(raw.get("rules"), raw.mark, concepts, ctx, problems, budget, depth + 1, parent)
    listen_s = DEFAULT_LISTEN_S
    raw_listen = raw.get("listen_s")
    if raw_listen is not None:
        listen_s = _number(raw_listen, problems, "listen_s", 1.0, 3600.0, DEFAULT_LISTEN_S, True)
    raw_otherwise = raw.get("otherwise")
    otherwise = _template(raw_otherwise, ctx, problems) if raw_otherwise is not None else None
    return FollowUp(rules, listen_s, otherwise)


def _rule(
    raw: YValue,
    concepts: dict[str, list[str]],
    ctx: CheckContext,
    problems: Problems,
    budget: Budget,
    depth: int,
    parent: str,
) -> DialogRule | None:
    if not isinstance(raw, YMap):
        problems.add(raw.mark, "each rule is a mapping with 'hear:' and 'say:'")
        return None
    problems.unknown_fields(raw.key_marks, _RULE_KEYS, "rule")
    hear = raw.get("hear")
    phrases: list[str] = []
    if hear is None:
        problems.add(raw.mark, "rule has no 'hear:'", "list the phrases that trigger it")
    else:
        items = hear.items if isinstance(hear, YList) else [hear]
        if not items:
            problems.add(hear.mark, "'hear' is empty", "list the phrases that trigger the rule")
        for item in items:
            if not isinstance(item, YScalar) or not isinstance(item.value, str) or not item.value:
                problems.add(item.mark, f"a phrase must be text, got {describe(item)}")
                continue
            expanded = expand(item.value, concepts)
            if isinstance(expanded, tuple):
                problems.add(item.mark, *expanded)
            elif len(expanded) > budget.left:
                if budget.left >= 0:  # said once, where the dialog goes over
                    problems.add(
                        item.mark,
                        f"the dialog's phrases expand to more than {MAX_DIALOG_EXPANSIONS} "
                        "phrases by here",
                        "use fewer ~concepts, or split the dialog in two",
                    )
                budget.left = -1
            else:
                budget.left -= len(expanded)
                phrases.extend(p for p in expanded if p)
    say = raw.get("say")
    answer = None
    if say is None:
        problems.add(raw.mark, "rule has no 'say:'", "write what the robot answers")
    else:
        answer = _template(say, ctx, problems)
    read = None
    raw_read = raw.get("read")
    if raw_read is not None:
        read = _text(raw_read, problems, "read")
        if read is not None and read not in ON_REQUEST_SENSORS:
            problems.add(
                raw_read.mark,
                f"cannot read {read!r} on request",
                did_you_mean(read, ON_REQUEST_SENSORS) or "use " + " or ".join(ON_REQUEST_SENSORS),
            )
            read = None
    unique = tuple(dict.fromkeys(phrases))
    rule_id = _text(raw.get("id"), problems, "id")
    if rule_id is None and unique:  # a follow-up's rule is named under its question's
        rule_id = f"{parent}/{unique[0]}" if parent else unique[0]
    raw_confirm = raw.get("confirm")
    confirm = (
        _template(raw_confirm, ctx, problems, "'confirm'") if raw_confirm is not None else None
    )
    raw_then = raw.get("then")
    follow_up = None
    if raw_then is not None:
        follow_up = _follow_up(raw_then, concepts, ctx, problems, budget, depth, rule_id or "?")
    if answer is None or not unique or rule_id is None:
        return None
    return DialogRule(
        id=rule_id,
        phrases=tuple(Phrase.of(text) for text in unique),
        answer=answer,
        read=read,
        follow_up=follow_up,
        mark=raw.mark,
        confirm=confirm,
    )


def _template(
    value: YValue, ctx: CheckContext, problems: Problems, what: str = "an answer"
) -> CompiledTemplate | None:
    """``value`` as what the robot says; ``what`` names it in a problem ("'confirm'")."""
    if not isinstance(value, YScalar) or not isinstance(value.value, str):
        problems.add(value.mark, f"{what} must be text, got {describe(value)}", "put it in quotes")
        return None
    if what != "an answer" and not value.value.strip():
        problems.add(value.mark, f"{what} is empty", "write what the robot says")
        return None
    try:
        return compile_template(value.value, ctx)
    except ParamProblem as problem:
        problems.add(value.mark, problem.message, problem.hint)
        return None
