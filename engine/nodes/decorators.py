"""Decorators: one child, changing what its status means or when it runs.

Timeout and Cooldown measure time on the engine clock, never the wall clock.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import py_trees
from py_trees.behaviour import Behaviour
from py_trees.common import OneShotPolicy, Status

from engine.clock import Clock
from engine.nodes.context import TreeContext
from engine.nodes.spec import NodeType
from engine.services.turns import TurnYieldedError
from engine.values.params import REQUIRED, SECONDS, Choice, Integer, Param


class EngineTimeout(py_trees.decorators.Decorator):
    """FAILURE when the child is still RUNNING ``seconds`` after it started."""

    def __init__(self, name: str, child: Any, seconds: float, clock: Clock) -> None:
        super().__init__(name=name, child=child)
        self.seconds = seconds
        self.clock = clock
        self.deadline_s = 0.0

    def initialise(self) -> None:
        self.deadline_s = self.clock.now() + self.seconds

    def update(self) -> Status:
        status = self.decorated.status
        if status == Status.RUNNING and self.clock.now() >= self.deadline_s:
            self.feedback_message = f"timed out after {self.seconds:g} s"
            return Status.FAILURE
        return status


class Cooldown(py_trees.decorators.Decorator):
    """After the child acted, FAILURE for ``seconds`` without ticking the child.

    The child acted when it succeeded, or when it failed after one of its actions ran
    (the LEDs failed but the robot spoke): the robot rests either way, rather than
    trying again on the next tick and stuttering. A child that failed before any action
    ran (a check inside it said no), or whose actions all let their turn go to a tree of
    higher priority (it did not act), starts no rest; nor does a child a higher tree
    interrupted (it is halted, not finished).

    ``counting_from`` is ``"end"`` (the rest starts when the child finished) or
    ``"start"`` (it starts when the child started: with a 5 s rest and 1.5 s of moves, a
    pat 5 s after the first one is answered).
    """

    def __init__(
        self, name: str, child: Any, seconds: float, clock: Clock, counting_from: str = "end"
    ) -> None:
        super().__init__(name=name, child=child)
        self.seconds = seconds
        self.clock = clock
        self.counting_from = counting_from
        self.ready_at_s = float("-inf")
        self.started_s = float("-inf")

    def initialise(self) -> None:
        self.started_s = self.clock.now()

    def tick(self) -> Any:
        remaining = self.ready_at_s - self.clock.now()
        if self.status != Status.RUNNING and remaining > 0:
            self.feedback_message = f"cooling down, {remaining:.1f} s left"
            self.stop(Status.FAILURE)
            yield self
            return
        yield from super().tick()

    def update(self) -> Status:
        status = self.decorated.status
        if status == Status.SUCCESS or (
            status == Status.FAILURE and _an_action_ran(self.decorated)
        ):
            since = self.started_s if self.counting_from == "start" else self.clock.now()
            self.ready_at_s = since + self.seconds
        self.feedback_message = ""
        return status


def _an_action_ran(node: Behaviour) -> bool:
    """Whether an action leaf under ``node`` acted in the round that just ended (its
    status is kept until the next round starts): it was ticked, asked a service, and did
    not let its turn go to another tree."""
    return any(
        getattr(leaf, "kind", None) == "action"
        and leaf.status != Status.INVALID
        and getattr(leaf, "job", None) is not None  # it asked a service (not SetValue, Wait)
        and not _lost_its_turn(leaf)
        for leaf in node.iterate()
    )


def _lost_its_turn(leaf: Behaviour) -> bool:
    job = getattr(leaf, "job", None)
    if job is None or getattr(job, "waiting", False):  # asking a waiting job starts it
        return False
    return job.done() and isinstance(job.error(), TurnYieldedError)


def _child(children: list[Any]) -> Any:
    return children[0]


def _inverter(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return py_trees.decorators.Inverter(name=name, child=_child(children))


def _force_success(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return py_trees.decorators.FailureIsSuccess(name=name, child=_child(children))


def _repeat(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return py_trees.decorators.Repeat(name=name, child=_child(children), num_success=args.times)


def _retry(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return py_trees.decorators.Retry(name=name, child=_child(children), num_failures=args.times)


def _timeout(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return EngineTimeout(name, _child(children), args.seconds, ctx.clock)


def _cooldown(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    return Cooldown(name, _child(children), args.seconds, ctx.clock, args.counting_from)


def _one_shot(name: str, args: SimpleNamespace, children: list[Any], ctx: TreeContext) -> Any:
    policy = (
        OneShotPolicy.ON_SUCCESSFUL_COMPLETION
        if args.after == "success"
        else OneShotPolicy.ON_COMPLETION
    )
    return py_trees.decorators.OneShot(name=name, child=_child(children), policy=policy)


DECORATORS = (
    NodeType(
        "Inverter",
        "decorator",
        """Swap the child's SUCCESS and FAILURE ("not").

        SUCCESS when the child failed; FAILURE when it succeeded; RUNNING while it runs.""",
        (),
        _inverter,
    ),
    NodeType(
        "ForceSuccess",
        "decorator",
        """Run the child; its failure does not count.

        SUCCESS when the child finished either way; RUNNING while it runs.""",
        (),
        _force_success,
    ),
    NodeType(
        "Repeat",
        "decorator",
        """Run the child again each time it succeeds, ``times`` times in all.

        SUCCESS after ``times`` successes; FAILURE as soon as the child fails; RUNNING
        in between.""",
        (Param("times", Integer(minimum=1), REQUIRED, "how many successes"),),
        _repeat,
    ),
    NodeType(
        "Retry",
        "decorator",
        """Try the child again when it fails, up to ``times`` failures.

        SUCCESS as soon as the child succeeds; FAILURE after ``times`` failures; RUNNING
        in between.""",
        (Param("times", Integer(minimum=1), REQUIRED, "how many failures to tolerate"),),
        _retry,
    ),
    NodeType(
        "Timeout",
        "decorator",
        """Give the child at most ``seconds`` to finish (engine clock).

        The child's status while it is in time; FAILURE (and the child stopped) when it is
        still RUNNING after ``seconds``.""",
        (Param("seconds", SECONDS, REQUIRED, "time allowed, in seconds"),),
        _timeout,
    ),
    NodeType(
        "Cooldown",
        "decorator",
        """After the child acted, rest for ``seconds`` so a behavior does not repeat itself.

        The rest counts from the end of the child's action (``counting_from: end``, the
        default) or from its start (``counting_from: start``: a 5 s rest around a 1.5 s arm
        move answers again 5 s after the last answer began).

        The child's status; FAILURE without ticking the child while cooling down.""",
        (
            Param("seconds", SECONDS, REQUIRED, "rest time, in seconds"),
            Param(
                "counting_from",
                Choice(("end", "start")),
                "end",
                "end: the rest starts when the child finished; start: when it started",
            ),
        ),
        _cooldown,
    ),
    NodeType(
        "OneShot",
        "decorator",
        """Run the child until it has finished once, then never again.

        The child's status until then; afterwards the status it finished with, forever.""",
        (
            Param(
                "after",
                Choice(("success", "completion")),
                "success",
                "success: only a success counts as done; completion: any finish does",
            ),
        ),
        _one_shot,
    ),
)
