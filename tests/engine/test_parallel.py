"""Parallel: children side by side, and a failing child never cuts the others short."""

from __future__ import annotations

from py_trees.behaviours import StatusQueue
from py_trees.common import Status

from engine.nodes.parallel import Parallel


def child(name: str, *statuses: Status) -> StatusQueue:
    """A child that answers ``statuses`` one tick after another, then the last one again."""
    return StatusQueue(name=name, queue=list(statuses), eventually=statuses[-1])


def tick(node: Parallel) -> Status:
    for _ in node.tick():
        pass
    return node.status


def test_a_child_that_fails_at_once_lets_its_sibling_finish_then_the_parallel_fails() -> None:
    led = child("led", Status.FAILURE)
    say = child("say", Status.RUNNING, Status.RUNNING, Status.SUCCESS)
    both = Parallel("both", [led, say])
    # ticks:     1        2        3
    # led:       FAILURE  (done)   (done)
    # say:       RUNNING  RUNNING  SUCCESS
    # parallel:  RUNNING  RUNNING  FAILURE
    assert [tick(both) for _ in range(3)] == [Status.RUNNING, Status.RUNNING, Status.FAILURE]
    assert both.feedback_message == "failed: led"


def test_all_children_succeeding_is_success() -> None:
    both = Parallel(
        "both", [child("a", Status.SUCCESS), child("b", Status.RUNNING, Status.SUCCESS)]
    )
    assert [tick(both) for _ in range(2)] == [Status.RUNNING, Status.SUCCESS]


def test_succeed_when_one_succeeds_with_the_first_and_halts_the_others() -> None:
    slow = child("slow", Status.RUNNING)
    both = Parallel("both", [child("fast", Status.SUCCESS), slow], succeed_when="one")
    assert tick(both) == Status.SUCCESS
    assert slow.status == Status.INVALID  # halted cleanly


def test_succeed_when_one_fails_only_when_every_child_failed() -> None:
    both = Parallel(
        "both",
        [child("a", Status.FAILURE), child("b", Status.RUNNING, Status.FAILURE)],
        succeed_when="one",
    )
    assert [tick(both) for _ in range(2)] == [Status.RUNNING, Status.FAILURE]


def test_a_new_round_starts_every_child_afresh() -> None:
    both = Parallel(
        "both", [child("a", Status.FAILURE, Status.SUCCESS), child("b", Status.SUCCESS)]
    )
    assert tick(both) == Status.FAILURE
    assert tick(both) == Status.SUCCESS  # round two: 'a' is ticked again and now succeeds


def test_no_children_is_success() -> None:
    assert tick(Parallel("empty", [])) == Status.SUCCESS


class Counted(StatusQueue):
    """A child that also counts its ticks."""

    ticks = 0

    def update(self) -> Status:
        self.ticks += 1
        return super().update()


def test_succeed_when_one_starts_no_child_after_the_one_that_succeeded() -> None:
    # the robot must not start saying something only to be cut short in the same tick
    late = Counted(name="late", queue=[Status.RUNNING], eventually=Status.RUNNING)
    both = Parallel("both", [child("fast", Status.SUCCESS), late], succeed_when="one")
    assert tick(both) == Status.SUCCESS
    assert late.ticks == 0
    assert late.status == Status.INVALID
