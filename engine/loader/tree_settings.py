"""A tree file's settings beside its root: how often it ticks and how it takes turns.

::

    rate_hz: 20            # ticks per second
    priority: 40           # higher interrupts lower for the speaker, face LEDs, joints
    wait_for_turn_s: 2     # how long an action waits for a busy resource (0: let it go)
    when_interrupted: try_again   # a round a higher tree cut short starts again (default:
                                  # let_go, the events that started it are spent)
    wake_on: [/sensors/touch/pat] # rest between rounds; tick at once when one changes
    interruptible: false   # a person speaking does not stop its sentences (default: true)

Each may be a ``${parameter}``, so a profile can set it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from engine.files.problems import Problems
from engine.files.yaml_source import YMap, plain
from engine.loader.substitution import ParamValue, substitute, unresolved
from engine.values.param_problems import CheckContext, ParamProblem
from engine.values.params import RATE_HZ, Boolean, Choice, Integer, Key, ListOf, Number, Param

DEFAULT_RATE_HZ = 10.0
PRIORITY = Integer(0, 99)
"""100 is the therapist's buttons': no tree outranks a press."""
WAIT_FOR_TURN_S = Number(0.0, 60.0, "s")
SETTINGS = (
    Param(
        "rate_hz",
        RATE_HZ,
        DEFAULT_RATE_HZ,
        f"ticks per second, from {RATE_HZ.minimum:g} to {RATE_HZ.maximum:g}, e.g. 10",
    ),
    Param(
        "priority",
        PRIORITY,
        0,
        "0..99: a tree of higher priority interrupts a lower one for the speaker, the "
        "face LEDs or a joint, e.g. priority: 40",
    ),
    Param(
        "wait_for_turn_s",
        WAIT_FOR_TURN_S,
        0.0,
        "seconds an action waits while another tree has the speaker, LEDs or joint "
        "(0: let the action go at once), e.g. wait_for_turn_s: 2",
    ),
    Param(
        "when_interrupted",
        Choice(("let_go", "try_again")),
        "let_go",
        "what a round that a higher tree cut short does: let_go (what started it is spent) "
        "or try_again (it starts again with the same events, its actions waiting up to "
        "wait_for_turn_s for their turn), e.g. when_interrupted: try_again",
    ),
    Param(
        "wake_on",
        ListOf(Key(kinds=("state", "event")), max_items=32),
        [],
        "blackboard keys whose change wakes the tree: it ticks at once (at most rate_hz "
        "times a second) and rests between rounds instead of ticking at its rate, e.g. "
        "wake_on: [/sensors/touch/pat, /sensors/force/squeeze]",
    ),
    Param(
        "interruptible",
        Boolean(),
        True,
        "whether a person who speaks over the robot stops this tree's sentences (true) "
        "or they always finish (false: an exercise that must be heard out), e.g. "
        "interruptible: false",
    ),
)


@dataclass(frozen=True)
class TreeSettings:
    rate_hz: float = DEFAULT_RATE_HZ
    priority: int = 0
    wait_for_turn_s: float = 0.0
    when_interrupted: str = "let_go"
    wake_on: tuple[str, ...] = ()
    interruptible: bool = True


def read_settings(
    document: YMap, params: dict[str, ParamValue], problems: Problems, ctx: CheckContext
) -> TreeSettings:
    """The settings of a tree file (defaults where absent or wrong; problems added)."""
    values: dict[str, Any] = {}
    for param in SETTINGS:
        value = read_setting(document, param, params, problems, ctx)
        values[param.name] = param.default if value is None else value
    values["wake_on"] = tuple(dict.fromkeys(values["wake_on"]))  # each key once
    return TreeSettings(**values)


def read_setting(
    document: YMap,
    param: Param[Any],
    params: dict[str, ParamValue],
    problems: Problems,
    ctx: CheckContext,
) -> Any:
    """One setting of a tree (or part) file, its ``${parameters}`` filled: None when it is
    absent or wrong (the problem added, with the setting's doc as the hint)."""
    raw = document.get(param.name)
    if raw is None:
        return None
    raw = substitute(raw, params, problems)
    if unresolved(raw):
        return None
    try:
        return param.type.convert(plain(raw), ctx)
    except ParamProblem as problem:
        problems.add(raw.mark, f"{param.name!r} {problem.message}", param.doc)
        return None
