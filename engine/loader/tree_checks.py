"""Checks across the trees a robot runs together: what would silently never work.

- a ``/vars/`` key read by a node but written by no tree never gets a value (a typo, most
  often): named with the nearest key that is written;
- a ``Check`` comparing a ``/vars/`` key with a value of another kind than the trees write
  (``equals: "true"`` where SetValue wrote ``true``) is never true;
- typographic quotes in spoken text (a warning: some voices read them out).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from engine.blackboard.catalogue import VARIABLES_PREFIX, KeyCatalogue
from engine.files.problems import Mark, Problem
from engine.loader.tree_definition import NodeDefinition, TreeDefinition
from engine.values.param_problems import did_you_mean
from engine.values.templates import CompiledTemplate

CURLY_QUOTES = re.compile("[\u2018\u2019\u201a\u201b\u201c\u201d\u201e\u201f\u2032\u2033]")
_SAVES_AS = {"OnTouch": str}
"""Nodes whose ``save_as`` value has a kind of its own (OnEvent: the event key's)."""


@dataclass(frozen=True)
class Write:
    """A node writing a ``/vars/`` key: where, and the kind of value (None: any)."""

    tree: str
    mark: Mark
    kind: type | None


def _kind(value: Any) -> type | None:
    if isinstance(value, bool):
        return bool
    if isinstance(value, int | float):
        return float
    if isinstance(value, str):
        return str
    return None


def variable_writes(trees: list[TreeDefinition], catalogue: KeyCatalogue) -> dict[str, list[Write]]:
    """Every ``/vars/`` key some tree writes, with each writer."""
    writes: dict[str, list[Write]] = {}
    for tree in trees:
        for node in tree.root.walk():
            _, written = node.type.keys(node.args)
            for key in written:
                if not key.startswith(VARIABLES_PREFIX):
                    continue
                kind: type | None = None
                if node.type.name == "SetValue":
                    kind = _kind(node.args.get("value"))
                elif node.type.name in _SAVES_AS:
                    kind = _SAVES_AS[node.type.name]
                elif isinstance(node.args.get("key"), str):
                    spec = catalogue.lookup(node.args["key"])
                    kind = _kind_of_type(spec.value_type) if spec is not None else None
                writes.setdefault(key, []).append(Write(tree.name, node.mark, kind))
    return writes


def _kind_of_type(value_type: type) -> type | None:
    return {bool: bool, float: float, int: float, str: str}.get(value_type)


def variable_problems(trees: list[TreeDefinition], catalogue: KeyCatalogue) -> list[Problem]:
    """Reads of ``/vars/`` keys no tree writes, and comparisons of the wrong kind."""
    writes = variable_writes(trees, catalogue)
    problems: list[Problem] = []
    for tree in trees:
        for node in tree.root.walk():
            read, _ = node.type.keys(node.args)
            for key in dict.fromkeys(k for k in read if k.startswith(VARIABLES_PREFIX)):
                if key not in writes:
                    hint = did_you_mean(key, list(writes)) or (
                        "a tree writes it with SetValue or save_as; none of these trees does"
                    )
                    problems.append(
                        Problem(node.mark, f"{key} is read but no tree writes it", hint)
                    )
            if node.type.name == "Check" and node.args.get("key") in writes:
                problems += _compared(node, writes[node.args["key"]])
    return problems


def _compared(node: NodeDefinition, writers: list[Write]) -> list[Problem]:
    kinds = {write.kind for write in writers}
    if None in kinds:
        return []  # some writer may store anything
    found: list[Problem] = []
    for name in ("equals", "not_equals"):
        value = node.args.get(name)
        kind = _kind(value)
        if value is None or kind in kinds:
            continue
        writer = writers[0]
        holds = {bool: "true/false", float: "a number", str: "text"}
        written = " or ".join(holds[k] for k in sorted(kinds, key=str) if k is not None)
        hint = "write true or false without quotes" if bool in kinds else f"compare with {written}"
        found.append(
            Problem(
                node.mark,
                f"{node.args['key']} holds {written} (written by tree {writer.tree!r} at "
                f"{writer.mark}), never {value!r}",
                hint,
            )
        )
    return found


def spoken_quote_warnings(trees: list[TreeDefinition]) -> list[str]:
    """Typographic quotes in what the robot says, each as a warning line with its place."""
    warnings: list[str] = []
    for tree in trees:
        for node in tree.root.walk():
            for value in node.args.values():
                text = value.source if isinstance(value, CompiledTemplate) else None
                if text is not None and CURLY_QUOTES.search(text):
                    warnings.append(
                        f"warning: {node.mark}: typographic quotes in {text!r} may be read out "
                        "by the voice (write ' and \" instead)"
                    )
    return warnings


def counting_warnings(trees: list[TreeDefinition]) -> list[str]:
    """A count or a hold put around what is not a question (an action: it would start
    again each tick), or a hold of an event (an event is a moment: it is never held)."""
    warnings: list[str] = []
    for tree in trees:
        for node in tree.root.walk():
            if node.type.name not in ("TimesWithin", "HeldFor"):
                continue
            under = [n for child in node.children for n in child.walk()]
            if any(n.type.kind == "action" for n in under):
                warnings.append(
                    f"warning: {node.mark}: {node.type.name} counts the answers of a question "
                    "(a Check, a pat, an event): put what the robot does after it, in a "
                    "Sequence, not under it"
                )
            elif node.type.name == "HeldFor" and any(
                n.type.name in ("OnTouch", "OnEvent") for n in under
            ):
                warnings.append(
                    f"warning: {node.mark}: an event (a pat, a word) is a moment and is never "
                    "held; HeldFor holds a Check (a force, a distance); to count events use "
                    "TimesWithin"
                )
    return warnings
