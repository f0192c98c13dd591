"""Our composites and decorators mean what BehaviorTree.CPP v4 means, where we say they do.

Each test builds one tree in both engines (ours from YAML by our loader, BehaviorTree.CPP
from XML through ``behaviortreepy``) with the same scripted leaves, ticks both and
compares, tick by tick, the root's status, the leaves ticked and the leaves halted. A
script is what a leaf answers to its own successive ticks: ``"RRS"`` is RUNNING, RUNNING,
SUCCESS, then SUCCESS again. Where docs/nodes.md ("How our nodes compare with
BehaviorTree.CPP") says we differ on purpose, the test asserts that difference.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from engine.nodes.bt_cpp_counterparts import COUNTERPARTS
from engine.nodes.registry import builtin_registry

from .two_engines import Node, Step, Theirs, ours, table, theirs

# what we say matches: our node type and YAML arguments <-> BehaviorTree.CPP's node and
# XML attributes
PAIRS: dict[str, tuple[str, dict[str, object], str, dict[str, str]]] = {
    "Sequence": ("Sequence", {}, "Sequence", {}),
    "Sequence memory false": ("Sequence", {"memory": False}, "ReactiveSequence", {}),
    "Selector": ("Selector", {}, "ReactiveFallback", {}),
    "Selector memory true": ("Selector", {"memory": True}, "Fallback", {}),
    "Parallel": ("Parallel", {}, "ParallelAll", {"max_failures": "1"}),
    "Parallel succeed_when one": (
        "Parallel",
        {"succeed_when": "one"},
        "Parallel",
        {"success_count": "1", "failure_count": "-1"},
    ),
    "Inverter": ("Inverter", {}, "Inverter", {}),
    "ForceSuccess": ("ForceSuccess", {}, "ForceSuccess", {}),
    "Repeat times 3": ("Repeat", {"times": 3}, "Repeat", {"num_cycles": "3"}),
    "Retry times 3": ("Retry", {"times": 3}, "RetryUntilSuccessful", {"num_attempts": "3"}),
    "Timeout not reached": ("Timeout", {"seconds": 100}, "Timeout", {"msec": "100000"}),
    "OneShot after completion": (
        "OneShot",
        {"after": "completion"},
        "RunOnce",
        {"then_skip": "false"},
    ),
}
COMPOSITES = [key for key in PAIRS if key.startswith(("Sequence", "Selector", "Parallel"))]
DECORATORS = [key for key in PAIRS if key not in COMPOSITES]
ROUNDS_AT_ONCE = ["Repeat times 3", "Retry times 3"]
"""Compared only with a child that finishes when first ticked: difference 2."""


def pair(key: str, *children: Node | str) -> Node:
    ours_type, args, theirs_type, attrs = PAIRS[key]
    return Node(ours_type, theirs_type, children, args, attrs)


def assert_same(tree: Node, scripts: dict[str, str], ticks: int, folder: Path) -> None:
    mine, reference = ours(tree, scripts, ticks, folder), theirs(tree, scripts, ticks)
    assert mine == reference, (
        f"scripts {scripts}\nours:\n{table(mine)}\nBehaviorTree.CPP:\n{table(reference)}"
    )


# -- composites ---------------------------------------------------------------------------
STORIES = {
    "every child succeeds at once": {"A": "S", "B": "S", "C": "S"},
    "every child fails at once": {"A": "F", "B": "F", "C": "F"},
    "the first fails, then succeeds next round": {"A": "FS", "B": "S", "C": "S"},
    "the first succeeds, then fails next round": {"A": "SF", "B": "F", "C": "S"},
    "the middle one runs, then succeeds": {"A": "S", "B": "RRS", "C": "S"},
    "the middle one runs, then fails": {"A": "F", "B": "RRF", "C": "F"},
    "the first stops succeeding while the second runs": {"A": "SSF", "B": "R", "C": "S"},
    "the first stops failing while the second runs": {"A": "FFS", "B": "R", "C": "F"},
    "the first starts running while the second runs": {"A": "SFRRS", "B": "R", "C": "S"},
    "the last one runs, then the first changes its mind": {"A": "SFSF", "B": "FS", "C": "R"},
    "all run, then finish one after another": {"A": "RS", "B": "RRRF", "C": "RRS"},
    "one fails while the others still run": {"A": "RRF", "B": "RS", "C": "RRRRS"},
    "one succeeds while the others still run": {"A": "RRS", "B": "RF", "C": "R"},
    "the first to run succeeds, the others never finish": {"A": "RS", "B": "R", "C": "R"},
}


@pytest.mark.parametrize("story", STORIES)
@pytest.mark.parametrize("composite", COMPOSITES)
def test_a_composite_of_three_leaves_ticks_and_halts_as_behaviortree_cpp(
    composite: str, story: str, tmp_path: Path
) -> None:
    assert_same(pair(composite, "A", "B", "C"), STORIES[story], 8, tmp_path)


MIXES = ["S", "F", "R", "RS", "RF", "SF", "FS", "SRF", "FRS"]


@pytest.mark.parametrize("composite", COMPOSITES)
def test_every_mix_of_two_scripted_leaves_agrees(composite: str, tmp_path: Path) -> None:
    for first, second in itertools.product(MIXES, repeat=2):
        assert_same(pair(composite, "A", "B"), {"A": first, "B": second}, 6, tmp_path)


# A reactive parent halts the running subtree when its first child A changes its mind,
# and starts it again when A changes back: every node cleans up and starts afresh alike.
PARENTS = {
    "Sequence memory false": ["SSFSS", "SFSFS"],
    "Selector": ["FFSFF", "FSFSF"],
}


@pytest.mark.parametrize("parent", PARENTS)
@pytest.mark.parametrize("inner", COMPOSITES)
def test_a_composite_halted_by_a_reactive_parent_halts_and_restarts_its_children_alike(
    parent: str, inner: str, tmp_path: Path
) -> None:
    tree = pair(parent, "A", pair(inner, "B", "C"))
    for first, second, third in itertools.product(
        PARENTS[parent], ["R", "RS", "RRF"], ["RS", "SR"]
    ):
        assert_same(tree, {"A": first, "B": second, "C": third}, 7, tmp_path)


# -- decorators ---------------------------------------------------------------------------
ONE_CHILD = ["S", "F", "R", "RS", "RF", "SF", "FS", "RSF", "RFS", "SSF", "FFS", "SSSF"]
AT_ONCE = ["S", "F", "R", "SF", "FS", "SSF", "FFS", "SSSF", "FFFS"]


@pytest.mark.parametrize("decorator", DECORATORS)
def test_a_decorator_ticks_and_halts_its_child_as_behaviortree_cpp(
    decorator: str, tmp_path: Path
) -> None:
    scripts = AT_ONCE if decorator in ROUNDS_AT_ONCE else ONE_CHILD
    for script in scripts:
        assert_same(pair(decorator, "A"), {"A": script}, 8, tmp_path)


@pytest.mark.parametrize("parent", PARENTS)
@pytest.mark.parametrize("decorator", DECORATORS)
def test_a_decorator_halted_by_a_reactive_parent_halts_and_restarts_its_child_alike(
    parent: str, decorator: str, tmp_path: Path
) -> None:
    tree = pair(parent, "A", pair(decorator, "B"))
    children = ["R", "SR", "FR"] if decorator in ROUNDS_AT_ONCE else ["R", "RS", "RRF", "SR"]
    for first, second in itertools.product(PARENTS[parent], children):
        assert_same(tree, {"A": first, "B": second}, 7, tmp_path)


# -- the names ----------------------------------------------------------------------------
def test_our_remembering_sequence_is_their_sequence_not_their_sequence_with_memory(
    tmp_path: Path,
) -> None:
    scripts = {"A": "S", "B": "FS", "C": "S"}
    ours_steps = ours(pair("Sequence", "A", "B", "C"), scripts, 2, tmp_path)
    with_memory = Node("Sequence", "SequenceWithMemory", ("A", "B", "C"))
    # after B failed, our Sequence starts again from A, as their Sequence does ...
    assert ours_steps == [Step("FAILURE", ticked="A B"), Step("SUCCESS", ticked="A B C")]
    assert theirs(pair("Sequence", "A", "B", "C"), scripts, 2) == ours_steps
    # ... where their SequenceWithMemory resumes at B, never asking A again (and it gives
    # back a tick after each child that succeeded at once)
    assert theirs(with_memory, scripts, 4) == [
        Step("RUNNING", ticked="A"),
        Step("FAILURE", ticked="B"),
        Step("RUNNING", ticked="B"),
        Step("SUCCESS", ticked="C"),
    ]


def test_every_composite_and_decorator_is_in_the_comparison_and_each_match_is_tested() -> None:
    ours_types = {t.name for t in builtin_registry() if t.kind in ("composite", "decorator")}
    assert {row.node_type for row in COUNTERPARTS} == ours_types
    compared = {theirs_type for _, _, theirs_type, _ in PAIRS.values()}
    for row in COUNTERPARTS:
        if row.theirs:
            assert row.theirs.strip("`").split("`")[0].split()[0] in compared, row


# -- a bug this comparison found ----------------------------------------------------------
def test_parallel_succeed_when_one_starts_no_child_after_the_one_that_succeeded(
    tmp_path: Path,
) -> None:
    # It ticked C after A had decided, only to halt it at once: a Say started and cut.
    tree = pair("Parallel succeed_when one", "A", "B", "C")
    first_wins = {"A": "S", "B": "R", "C": "R"}
    expected = [Step("SUCCESS", ticked="A")]
    assert ours(tree, first_wins, 1, tmp_path) == expected == theirs(tree, first_wins, 1)
    # when A succeeds later, B and C (running) are halted and not ticked again first
    a_runs_first = {"A": "RS", "B": "R", "C": "R"}
    expected = [Step("RUNNING", ticked="A B C"), Step("SUCCESS", ticked="A", halted="B C")]
    assert ours(tree, a_runs_first, 2, tmp_path) == expected == theirs(tree, a_runs_first, 2)


# -- differences on purpose (docs/nodes.md, numbered as there) ---------------------------
def test_1_parallel_synchronise_false_ticks_a_child_that_succeeded_again(
    tmp_path: Path,
) -> None:
    tree = Node(
        "Parallel", "ParallelAll", ("A", "B"), {"synchronise": False}, {"max_failures": "1"}
    )
    scripts = {"A": "SF", "B": "RRS"}
    # ours: A succeeded at tick 1, is asked again at tick 2 and changes its mind
    assert ours(tree, scripts, 3, tmp_path) == [
        Step("RUNNING", ticked="A B"),
        Step("RUNNING", ticked="A B"),
        Step("FAILURE", ticked="B"),
    ]
    # theirs: a finished child is never ticked again in the round
    assert theirs(tree, scripts, 3) == [
        Step("RUNNING", ticked="A B"),
        Step("RUNNING", ticked="B"),
        Step("SUCCESS", ticked="B"),
    ]


def test_2_repeat_starts_the_next_round_on_the_next_tick(tmp_path: Path) -> None:
    tree = pair("Repeat times 3", "A")
    scripts = {"A": "RSRSRS"}  # each round: RUNNING, then SUCCESS
    assert ours(tree, scripts, 6, tmp_path) == [
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A"),  # round 1 succeeded; round 2 waits for the next tick
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A"),
        Step("SUCCESS", ticked="A"),
    ]
    assert theirs(tree, scripts, 4) == [
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A A"),  # round 2 starts in the tick round 1 ended
        Step("RUNNING", ticked="A A"),
        Step("SUCCESS", ticked="A"),
    ]


def test_2_retry_tries_again_on_the_next_tick(tmp_path: Path) -> None:
    tree = pair("Retry times 3", "A")
    scripts = {"A": "RFRS"}
    assert ours(tree, scripts, 4, tmp_path) == [
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A"),  # attempt 1 failed; attempt 2 waits for the next tick
        Step("RUNNING", ticked="A"),
        Step("SUCCESS", ticked="A"),
    ]
    assert theirs(tree, scripts, 3) == [
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A A"),  # attempt 2 starts in the tick attempt 1 failed
        Step("SUCCESS", ticked="A"),
    ]


def test_3_timeout_decides_at_the_tick_on_the_engine_clock(tmp_path: Path) -> None:
    # ours, 10 ticks a second, 0.25 s allowed: the tick at 0.3 s still ticks A, then halts it
    timeout = Node("Timeout", "Timeout", ("A",), {"seconds": 0.25})
    assert ours(timeout, {"A": "R"}, 4, tmp_path) == [
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A"),
        Step("RUNNING", ticked="A"),
        Step("FAILURE", ticked="A", halted="A"),
    ]
    # a child that finishes in that tick is in time
    assert ours(timeout, {"A": "RRRS"}, 4, tmp_path)[-1] == Step("SUCCESS", ticked="A")

    # theirs: the timer thread halts A between ticks; the next tick fails without it
    engine = Theirs(Node("Timeout", "Timeout", ("A",), attrs={"msec": "1"}), {"A": "R"})
    assert engine.tick() == Step("RUNNING", ticked="A")
    assert engine.wait_for_a_halt() == ["A"]
    assert engine.tick() == Step("FAILURE", ticked="", halted="A")  # the halt before it


def test_4_oneshot_after_success_tries_again_after_a_failure(tmp_path: Path) -> None:
    scripts = {"A": "FS"}
    oneshot = Node("OneShot", "RunOnce", ("A",), {}, {"then_skip": "false"})
    assert ours(oneshot, scripts, 3, tmp_path) == [
        Step("FAILURE", ticked="A"),
        Step("SUCCESS", ticked="A"),  # the failure did not count
        Step("SUCCESS", ticked=""),  # done: the child is never ticked again
    ]
    assert theirs(oneshot, scripts, 3) == [
        Step("FAILURE", ticked="A"),
        Step("FAILURE", ticked=""),  # the first result stays, whatever it was
        Step("FAILURE", ticked=""),
    ]
