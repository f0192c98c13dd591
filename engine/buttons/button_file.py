"""Button files: what each of the therapist's buttons makes the robot do.

::

    buttons:
      - label: Hello                       # what the button says
        key: h                             # a keyboard key presses it too
        say: "Hi! I am happy to see you."  # or {text: ..., volume: 0.8}
      - label: Happy face
        led: {color: green, seconds: 3}    # or a color: led: green
      - label: Look at me
        move: {joint: neck, angle_deg: 0}
      - label: Wave
        play: ../parts/greet.yaml          # a tree file (its root), relative to this file
        params: {phrase: "Hello!"}
      - label: Count with me
        when: {running: finger_game}       # shown only while that tree runs
        say: "How many fingers do you see?"
      - label: Pause
        key: p
        do: pause                          # pause | resume | stop

A button does one thing: ``say``, ``led``, ``move``, ``play`` (with ``params``) or ``do``.
``when`` shows it only when it makes sense: ``{running: TREE}``, ``{paused: true}``, or a
blackboard comparison ``{key: ..., equals | not_equals | above | below: ...}``. Pause shows
only while the robot is not paused, resume only while it is, unless ``when`` says more.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

from engine.files.problems import LoadError, Mark, Problems
from engine.files.yaml_source import YList, YMap, YScalar, YValue, describe, load_yaml, plain
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.session.events import ButtonControl
from engine.values.param_problems import did_you_mean

ACTIONS = ("say", "led", "move", "play", "do")
CONTROLS = ("pause", "resume", "stop")
FIELDS = ("label", "key", "when", "params", *ACTIONS)
NAMED_KEYS = ("Escape", "Enter", "Space", *(f"F{n}" for n in range(1, 13)))
_NODE_OF = {"say": ("Say", "text"), "led": ("SetLed", "color"), "move": ("MoveServo", None)}
COMPARISONS = ("equals", "not_equals", "above", "below")
BUTTONS_TREE = "buttons"
"""The name of the tree a button's action runs on (the timeline's ``buttons`` lines)."""
BUTTON_PRIORITY = 100
"""A button's action outranks every tree: it interrupts whatever holds what it needs."""
BUTTON_RATE_HZ = 20.0
"""How often the buttons' tree ticks: a press is answered within 50 ms."""


@dataclass(frozen=True)
class When:
    """When a button is shown: while a tree runs, while paused, or a key's comparison."""

    running: str | None = None
    paused: bool | None = None
    key: str | None = None
    comparison: str | None = None
    value: Any = None


@dataclass(frozen=True)
class Button:
    """One button: its label and key, and either a tree to run or a control."""

    number: int
    label: str
    key: str | None
    mark: Mark
    tree: TreeDefinition | None = None
    control: ButtonControl | None = None
    when: When | None = None

    def to_json(self) -> dict[str, Any]:
        return {"id": self.number, "label": self.label, "key": self.key, "control": self.control}


@dataclass(frozen=True)
class ButtonBoard:
    """Every button of a file, in order, and the buttons' tree between presses (``idle``:
    nothing to do)."""

    path: Path
    buttons: tuple[Button, ...]
    idle: TreeDefinition

    def button(self, number: int) -> Button | None:
        return self.buttons[number] if 0 <= number < len(self.buttons) else None


def load_buttons(path: Path, loader: TreeLoader) -> ButtonBoard:
    """Validate a button file: every button, its action's nodes with ``loader`` (against
    the robot's nodes, keys and dialogs); LoadError listing every problem."""
    problems = Problems()
    document = load_yaml(path)
    example = "e.g. buttons: [{label: Hello, key: h, say: Hi!}]"
    where = document.mark if document is not None else Mark(str(path), 1, 1)
    if not isinstance(document, YMap) or not isinstance(document.get("buttons"), YList):
        problems.add(where, "a button file is a mapping with a list 'buttons:'", example)
        problems.raise_if_any()
    assert isinstance(document, YMap)
    problems.unknown_fields(document.key_marks, ("buttons", "description"))
    listed = document.get("buttons")
    assert isinstance(listed, YList)
    buttons: list[Button] = []
    labels: dict[str, Mark] = {}
    keys: dict[str, str] = {}
    for raw in listed:
        button = _button(raw, len(buttons), path, loader, problems)
        if button is None:
            continue
        if button.label in labels:
            problems.add(button.mark, f"two buttons are labelled {button.label!r}", "rename one")
        labels[button.label] = button.mark
        if button.key is not None and button.key in keys:
            problems.add(
                button.mark,
                f"key {button.key!r} is taken by button {keys[button.key]!r}",
                "give each button its own key",
            )
        if button.key is not None:
            keys[button.key] = button.label
        buttons.append(button)
    if not buttons and not problems:
        problems.add(listed.mark, "'buttons' lists no button", example)
    problems.raise_if_any()
    here = listed.mark
    nothing = YMap({"seconds": YScalar(0.0, here)}, here, {"seconds": here})
    idle = loader.load_node(
        YMap({"Wait": nothing}, here, {"Wait": here}),
        path,
        name=BUTTONS_TREE,
        rate_hz=BUTTON_RATE_HZ,
        priority=BUTTON_PRIORITY,
    )
    return ButtonBoard(path, tuple(buttons), idle)


def _text(raw: YValue | None) -> str | None:
    value = plain(raw) if raw is not None else None
    return str(value).strip() if isinstance(value, str | int | float) and value != "" else None


def _button(
    raw: YValue, number: int, path: Path, loader: TreeLoader, problems: Problems
) -> Button | None:
    if not isinstance(raw, YMap):
        problems.add(
            raw.mark, f"a button is a mapping, got {describe(raw)}", "e.g. {label: Hi, say: Hi!}"
        )
        return None
    problems.unknown_fields(raw.key_marks, FIELDS, "button")
    label = _text(raw.get("label"))
    if label is None:
        problems.add(raw.mark, "a button needs a 'label'", "e.g. label: Hello")
        return None
    key = _key(raw.get("key"), problems)
    given = [action for action in ACTIONS if action in raw]
    if len(given) != 1:
        problems.add(
            raw.mark,
            f"button {label!r} must do one thing: "
            + ("nothing is given" if not given else f"it gives {', '.join(given)}"),
            "one of " + ", ".join(ACTIONS),
        )
        return None
    action = given[0]
    when = _when(raw.get("when"), problems, loader)
    body = raw.entries[action]
    if action == "do":
        control = plain(body)
        if control not in CONTROLS:
            problems.add(
                body.mark,
                f"do: must be one of {', '.join(CONTROLS)}, got {describe(body)}",
                did_you_mean(str(control), CONTROLS) if isinstance(control, str) else None,
            )
            return None
        return Button(number, label, key, raw.mark, control=cast(ButtonControl, control), when=when)
    node = _node(action, body, raw, problems)
    if node is None:
        return None
    try:
        tree = loader.load_node(
            node, path, name=BUTTONS_TREE, rate_hz=BUTTON_RATE_HZ, priority=BUTTON_PRIORITY
        )
    except LoadError as error:
        problems.extend(error.problems)
        return None
    return Button(number, label, key, raw.mark, tree=tree, when=when)


def _key(raw: YValue | None, problems: Problems) -> str | None:
    if raw is None:
        return None
    key = plain(raw)
    text = str(key) if isinstance(key, str | int) and not isinstance(key, bool) else ""
    if len(text) == 1 and text.isprintable() and text != " ":
        return text.lower()
    if text in NAMED_KEYS:
        return text
    hint = did_you_mean(text, NAMED_KEYS) or "one letter or digit, or " + ", ".join(NAMED_KEYS)
    problems.add(raw.mark, f"key {describe(raw)} is not a key of the keyboard", hint)
    return None


def _node(action: str, body: YValue, button: YMap, problems: Problems) -> YMap | None:
    """The node a button's action is, as a tree file would write it (marks kept)."""
    if action == "play":
        if not isinstance(body, YScalar) or not isinstance(body.value, str):
            problems.add(
                body.mark,
                f"play: takes a tree file, got {describe(body)}",
                "e.g. play: parts/greet.yaml",
            )
            return None
        entries: dict[str, YValue] = {"file": body}
        if button.get("params") is not None:
            entries["params"] = button.entries["params"]
        marks = {name: button.key_marks.get(name, body.mark) for name in entries}
        subtree = YMap(entries, body.mark, marks)
        return YMap({"Subtree": subtree}, body.mark, {"Subtree": button.key_marks["play"]})
    if button.get("params") is not None:
        problems.add(button.key_marks["params"], "params: goes with play:, not with " + action)
        return None
    node_type, short = _NODE_OF[action]
    if isinstance(body, YScalar) and short is not None:
        body = YMap({short: body}, body.mark, {short: body.mark})
    return YMap({node_type: body}, body.mark, {node_type: button.key_marks[action]})


def _when(raw: YValue | None, problems: Problems, loader: TreeLoader) -> When | None:
    if raw is None:
        return None
    example = "e.g. when: {running: finger_game} or {key: /vars/game/round, above: 2}"
    if not isinstance(raw, YMap):
        problems.add(raw.mark, f"when: must be a mapping, got {describe(raw)}", example)
        return None
    problems.unknown_fields(raw.key_marks, ("running", "paused", "key", *COMPARISONS), "when")
    given = [name for name in ("running", "paused", "key") if name in raw]
    if len(given) > 1:
        problems.add(raw.mark, f"when: takes one condition, got {', '.join(given)}", example)
        return None
    if "running" in raw:
        running = plain(raw.entries["running"])
        if not isinstance(running, str) or not running.strip():
            problems.add(raw.entries["running"].mark, "running: takes a tree's name", example)
            return None
        return When(running=running.strip())
    if "paused" in raw:
        paused = plain(raw.entries["paused"])
        if not isinstance(paused, bool):
            problems.add(
                raw.entries["paused"].mark,
                f"paused: must be true or false, got {paused!r}",
                "write true or false without quotes",
            )
            return None
        return When(paused=paused)
    key = _text(raw.get("key"))
    compared = [name for name in COMPARISONS if name in raw]
    if key is None or len(compared) != 1:
        problems.add(
            raw.mark, "when: needs running:, paused:, or a key with one comparison", example
        )
        return None
    if loader.catalogue.lookup(key) is None:
        hint = loader.catalogue.suggest(key)
        problems.add(
            raw.entries["key"].mark,
            f"unknown blackboard key {key!r}",
            f"did you mean {hint!r}?" if hint else "see `vest keys`",
        )
        return None
    value = plain(raw.entries[compared[0]])
    if compared[0] in ("above", "below") and (
        isinstance(value, bool) or not isinstance(value, int | float)
    ):
        problems.add(
            raw.entries[compared[0]].mark, f"{compared[0]}: must be a number, got {value!r}"
        )
        return None
    return When(key=key, comparison=compared[0], value=value)
