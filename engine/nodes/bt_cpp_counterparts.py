"""How our composites and decorators compare with BehaviorTree.CPP v4 (docs/nodes.md).

Each row names one of our node types, as written in YAML, and the BehaviorTree.CPP node
it means, as written in its XML. tests/nodes/test_same_as_behaviortree_cpp.py builds each
pair in both engines (BehaviorTree.CPP through its Python bindings, ``behaviortreepy``)
with the same scripted leaves, and compares them tick by tick; where a row says they
differ, that test asserts the difference written here.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Counterpart:
    """One of our node types (with the settings that choose a meaning) and its match."""

    node_type: str
    ours: str
    """How it is written in our YAML, e.g. ``Sequence`` with ``memory: false``."""
    theirs: str
    """The BehaviorTree.CPP v4 node, as written in its XML; empty when it has none."""
    tick_by_tick: str
    """``the same``, or which difference (by number) applies."""


COUNTERPARTS: tuple[Counterpart, ...] = (
    Counterpart(
        "Sequence",
        "`Sequence` (memory: true, the default)",
        "`Sequence` (not `SequenceWithMemory`, which after a failure resumes at the "
        "failed child; ours starts again from the first)",
        "the same",
    ),
    Counterpart("Sequence", "`Sequence` with memory: false", "`ReactiveSequence`", "the same"),
    Counterpart(
        "Selector", "`Selector` (memory: false, the default)", "`ReactiveFallback`", "the same"
    ),
    Counterpart("Selector", "`Selector` with memory: true", "`Fallback`", "the same"),
    Counterpart(
        "Parallel",
        "`Parallel` (succeed_when: all, the default)",
        '`ParallelAll max_failures="1"`',
        "the same; with synchronise: false, difference 1",
    ),
    Counterpart(
        "Parallel",
        "`Parallel` with succeed_when: one",
        '`Parallel success_count="1" failure_count="-1"`',
        "the same",
    ),
    Counterpart("Inverter", "`Inverter`", "`Inverter`", "the same"),
    Counterpart("ForceSuccess", "`ForceSuccess`", "`ForceSuccess`", "the same"),
    Counterpart("Repeat", "`Repeat` times: N", '`Repeat num_cycles="N"`', "difference 2"),
    Counterpart(
        "Retry", "`Retry` times: N", '`RetryUntilSuccessful num_attempts="N"`', "difference 2"
    ),
    Counterpart(
        "Timeout",
        "`Timeout` seconds: S",
        '`Timeout msec="1000 * S"`',
        "the same until the time is up; then difference 3",
    ),
    Counterpart(
        "OneShot",
        "`OneShot` with after: completion",
        '`RunOnce then_skip="false"`',
        "the same; with after: success (the default), difference 4",
    ),
    Counterpart("Cooldown", "`Cooldown`", "", "none: BehaviorTree.CPP has no such node"),
    Counterpart("TimesWithin", "`TimesWithin`", "", "none: BehaviorTree.CPP has no such node"),
    Counterpart("HeldFor", "`HeldFor`", "", "none: BehaviorTree.CPP has no such node"),
)

DIFFERENCES: tuple[str, ...] = (
    "**Parallel, synchronise: false** ticks again a child that already succeeded, so a "
    "condition under it can change its mind while its siblings run; BehaviorTree.CPP's "
    "ParallelAll never ticks a finished child again in the same round.",
    "**Repeat and Retry start the child's next round on the next tick.** BehaviorTree.CPP "
    "starts it within the same tick when the round that just ended had been RUNNING (after "
    "a round that finished at once it waits a tick, as we do). Why: our blackboard changes "
    "only between ticks, so an attempt made in the same tick would see the very readings "
    "that made the last one fail; and one round per tick keeps a tick's work bounded.",
    "**Timeout decides when it is ticked, on the engine clock.** The first tick after the "
    "time is up still ticks the child: if it finished then, its status counts; if it is "
    "still RUNNING, it is halted and the Timeout fails. BehaviorTree.CPP's timer thread "
    "halts the child at the moment the wall clock says so, between ticks, and the next "
    "tick fails without ticking it. Why: our nodes run only inside a tick (a halt from "
    "another thread would race the tick and the services), and a virtual clock makes tests "
    "and replays exact; the price is one tick period of precision.",
    "**OneShot, after: success (the default)** runs the child again after a failure: a "
    "greeting the robot could not say (the speaker was busy) is tried again. RunOnce keeps "
    "whatever the child first finished with, as after: completion does. We have no SKIPPED "
    'status (py_trees has none), so RunOnce\'s default then_skip="true" has no match.',
)

NOTES: tuple[str, ...] = (
    "Both engines are ticked exactly once per step in the comparison (BehaviorTree.CPP's "
    "`tickExactlyOnce`): its usual `tickOnce` ticks the tree again at once when a node asks "
    "to be woken up, which our scheduler never does: a tree ticks at its `rate_hz`.",
    "Only in BehaviorTree.CPP: SKIPPED, ForceFailure, KeepRunningUntilFailure, Delay, "
    "Precondition, Switch, IfThenElse, WhileDoElse, and Parallel thresholds other than the "
    "two above. Only here: Cooldown, TimesWithin, HeldFor, OneShot's after: success, "
    "Parallel's synchronise: false.",
)


def comparison_markdown() -> list[str]:
    """The "How our nodes compare with BehaviorTree.CPP" section, as Markdown lines."""
    lines = [
        "## How our nodes compare with BehaviorTree.CPP",
        "",
        "Our composites and decorators mean what these BehaviorTree.CPP v4 nodes mean.",
        "`tests/nodes/test_same_as_behaviortree_cpp.py` builds each pair in both engines",
        "(BehaviorTree.CPP through `behaviortreepy`) with the same scripted leaves, ticks them",
        "and compares, tick by tick, the root's status, the leaves ticked and the leaves",
        "halted; each difference below is asserted there, on purpose.",
        "",
        "| ours | BehaviorTree.CPP v4 | tick by tick |",
        "|---|---|---|",
    ]
    lines += [f"| {c.ours} | {c.theirs or '-'} | {c.tick_by_tick} |" for c in COUNTERPARTS]
    lines += ["", "Differences on purpose:", ""]
    lines += [f"{number}. {text}" for number, text in enumerate(DIFFERENCES, start=1)]
    lines += [""] + [f"- {note}" for note in NOTES]
    return lines
