"""The scheduler: every tree ticks at its own fixed rate, on drift-free deadlines.

Deadlines are ``origin + k * period`` (never "last tick + period"), so small delays do
not add up. Before the trees due at a deadline tick, the hooks run (the scenario, hot
reload) and the blackboard's staged writes are committed: every tree ticked at one
deadline sees the same snapshot. A tick that overran whole periods skips them (counted).

A tree that says what wakes it (``wake_on:``, keys) rests between rounds: once a tick
finds nothing to do (its root FAILURE: the condition that starts it not met; after a
round that acted, the next tick) it is not ticked at its deadlines, until one of those keys
changes (a producer stages a new value or an event, or another tree writes it); then the
scheduler steps at once and the tree ticks, no sooner than a period after its last tick
(``rate_hz`` stays its fastest), and at its rate while the round runs.

Within one step the trees due tick in order of priority, highest first (the therapist's
buttons, then the behaviors): what several trees claim at one moment (the speaker, the
face LEDs, a joint) is settled by priority before a lower tree starts anything, never by
a tree's name or the order the trees were loaded. Trees of one priority keep the order
they were added in (``vest validate`` warns when two of them can want one resource).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import py_trees

from engine.blackboard.board import Blackboard
from engine.clock import Clock, stopwatch
from engine.errors import ConfigError
from engine.loader.tree_definition import TreeDefinition
from engine.nodes.context import TreeContext
from engine.runtime.stats import TickStats
from engine.runtime.tree_events import TreeEvents
from engine.values.params import RATE_HZ

_log = logging.getLogger("vest.scheduler")

Hook = Callable[[float], None]


@dataclass
class RunningTree:
    """A built tree with its rate, next deadline and statistics."""

    definition: TreeDefinition
    context: TreeContext
    tree: py_trees.trees.BehaviourTree
    origin_s: float = 0.0
    period_index: int = 0
    stats: TickStats = field(default_factory=TickStats)
    paused: bool = False
    """A paused tree keeps its deadlines but is not ticked (the therapist paused it)."""
    retrying: bool = False
    """The round under way is one cut short and tried again (it is tried again once)."""
    resting: bool = False
    """A tree with ``wake_on`` between rounds: its deadlines pass until a key wakes it."""
    woken: bool = False
    """One of its keys changed since its round began: it ticks (a new round) as soon as
    its rate allows."""
    last_tick_s: float = -math.inf
    _events: TreeEvents | None = None

    @property
    def name(self) -> str:
        return self.definition.name

    @property
    def period_s(self) -> float:
        return 1.0 / self.definition.rate_hz

    @property
    def next_deadline_s(self) -> float:
        return self.origin_s + self.period_index * self.period_s

    @property
    def priority(self) -> int:
        return self.definition.priority

    @property
    def status(self) -> py_trees.common.Status:
        return self.tree.root.status

    @property
    def tries_again(self) -> bool:
        """Whether a round cut short by a higher tree is started again (``when_interrupted:
        try_again``) rather than let go."""
        return self.definition.when_interrupted == "try_again"

    @property
    def events(self) -> TreeEvents:
        """Its event readers, read as one (found again for a new version)."""
        if self._events is None or self._events.root is not self.tree.root:
            self._events = TreeEvents(self.tree.root, self.context.blackboard)
        return self._events

    def try_again(self) -> None:
        """Hand the events of the round that was cut short back to its nodes: at its next
        tick the tree starts the round again as if they had just come (``retrying`` until
        a round ends)."""
        self.events.back_to_round_start()
        self.retrying = True

    def replace(self, definition: TreeDefinition) -> None:
        """Swap in a new version of the tree between ticks (statistics kept).

        The new tree is built first: if building fails, the running tree is untouched.
        """
        self.swap(definition, definition.build(self.context))

    def swap(
        self,
        definition: TreeDefinition,
        new_tree: py_trees.trees.BehaviourTree,
        *,
        keep_events: bool = False,
    ) -> None:
        """Swap in ``new_tree``, built from ``definition`` (beside the scheduler, for hot
        reload), halting the running one cleanly; call between ticks. ``keep_events``: its
        nodes take up each key's events where the old version stood (a word or a command
        that came while it was built, one handed back to try again, is not lost)."""
        old_root = self.tree.root
        self.halt("its tree was replaced")
        stood = self.events.places() if keep_events else {}
        for node in old_root.iterate():  # the old nodes' blackboard clients go with them
            for client in node.blackboards:
                client.unregister(clear=False)
        self.origin_s = self.next_deadline_s
        self.period_index = 0
        self.resting = self.woken = False  # the new version's first round starts now
        self.definition = definition
        self.tree = new_tree
        self.events.take_up(stood)
        actions = self.context.actions
        if actions.taking is not None:  # the new version's priority and patience
            actions.taking = replace(
                actions.taking,
                priority=definition.priority,
                wait_for_turn_s=definition.wait_for_turn_s,
                interruptible=definition.interruptible,
            )

    def halt(
        self,
        why: str = "its tree was stopped",
        *,
        tried_again: bool = False,
        heard_last: bool = False,
    ) -> None:
        """Stop whatever is running (cancels service jobs: speech, moves, lights; each is
        told as cut short, ``why``), then send the joints it moved back to rest and turn
        off the LEDs it lit. Its nodes see, while they stop: ``tried_again``, the round
        starts again at once; ``heard_last``, a person spoke over the last sentence of
        what it was saying."""
        root = self.tree.root
        if root.status == py_trees.common.Status.RUNNING:
            actions = self.context.actions
            actions.stop_reason, actions.round_tried_again = why, tried_again
            actions.last_sentence_heard = heard_last
            try:
                root.stop(py_trees.common.Status.INVALID)
            finally:
                actions.stop_reason, actions.round_tried_again = "", False
                actions.last_sentence_heard = False
            actions.settle()
            if not tried_again:
                self.events.round_ends()


class Scheduler:
    """Ticks trees at their rates on the injected clock until stopped."""

    def __init__(
        self,
        clock: Clock,
        blackboard: Blackboard,
        *,
        hooks: list[Hook] | None = None,
        measure: Callable[[], float] = stopwatch,
    ) -> None:
        self.clock = clock
        self.blackboard = blackboard
        self.hooks = hooks if hooks is not None else []
        self.after_tick: list[Callable[[RunningTree], None]] = []
        """Called with each tree right after it ticked (a recorder noting what changed);
        one that raises is logged and the robot goes on."""
        self.trees: list[RunningTree] = []
        self._measure = measure
        self._stop = clock.event()
        self._attention = clock.event()
        self._wake_keys_of: tuple[TreeDefinition, ...] = ()
        """Set by a stop, and by a change to a key a resting tree wakes on."""
        self.hook_errors = 0

    def add_hook(self, hook: Hook, *, first: bool = False) -> None:
        """Run ``hook`` before each step's ticks, after those added before it (``first``:
        before all of them: the scenario, which moves the world the others read)."""
        if first:
            self.hooks.insert(0, hook)
        else:
            self.hooks.append(hook)

    def add(self, tree: RunningTree) -> RunningTree:
        """Schedule ``tree``; trees added before the run share one origin for their deadlines.

        A rate the loader would refuse (a tree built in code) is refused here too, so every
        deadline is finite: 5e-324 Hz is a period of inf and a deadline of NaN.
        """
        rate_hz = tree.definition.rate_hz
        if not (RATE_HZ.minimum or 0.0) <= rate_hz <= (RATE_HZ.maximum or math.inf):
            raise ConfigError(
                f"tree {tree.name!r}: rate_hz must be {RATE_HZ.minimum:g}..{RATE_HZ.maximum:g},"
                f" got {rate_hz!r}"
            )
        started = any(t.stats.ticks for t in self.trees)
        tree.origin_s = self.clock.now() if started or not self.trees else self.trees[0].origin_s
        tree.period_index = 0
        self.trees.append(tree)
        self.blackboard.on_wake = self._attention.set
        self._listen_for_wake_keys()
        return tree

    def _listen_for_wake_keys(self) -> None:
        """Tell the blackboard which keys wake a tree (again after a reload changed them)."""
        definitions = tuple(tree.definition for tree in self.trees)
        if definitions != self._wake_keys_of:
            self._wake_keys_of = definitions
            keys = (key for definition in definitions for key in definition.wake_on)
            self.blackboard.wake_keys = frozenset(keys)

    def tree(self, name: str) -> RunningTree:
        for tree in self.trees:
            if tree.name == name:
                return tree
        raise KeyError(f"no tree named {name!r}")

    def stop(self) -> None:
        """Ask the loop to end after the current tick (safe from a signal handler); only
        the scheduler's own wait is cut short, never a driver's or a poller's sleep."""
        self._stop.set()
        self._attention.set()

    def next_deadline_s(self) -> float:
        return min(tree.next_deadline_s for tree in self.trees)

    def run(
        self,
        *,
        until_s: float | None = None,
        start_s: float | None = None,
        halt_at_end: bool = True,
    ) -> None:
        """Tick until :meth:`stop` or, when given, until clock time ``until_s``; then halt
        every tree (the robot stops: joints to rest, LEDs off), unless ``halt_at_end`` is
        False (a test running the robot a while at a time).

        On the first run every tree's first deadline is ``start_s`` (default: now), so
        trees of one rate tick together (one wake-up, one snapshot) and none starts late;
        producers that pace themselves on the trees (pollers) are given the same origin.
        """
        if not self.trees:
            raise ValueError("no trees to run")
        if not any(tree.stats.ticks for tree in self.trees):
            start = self.clock.now() if start_s is None else start_s
            for tree in self.trees:
                tree.origin_s, tree.period_index = start, 0
        try:
            while not self._stop.is_set():
                deadline = self.next_deadline_s()
                if until_s is not None and deadline > until_s:
                    self.clock.sleep_until(until_s, self._stop)
                    break
                if self.clock.sleep_until(deadline, self._attention):
                    if self._stop.is_set():
                        break
                    self._attention.clear()  # a key woke a resting tree: step now
                self.step()
        finally:
            for tree in self.trees if halt_at_end else ():  # nothing goes on after the run
                try:
                    tree.halt()
                except Exception as error:  # a terminate() failing must not hide the others
                    _log.error(
                        "%s: stopping failed: %s: %s", tree.name, type(error).__name__, error
                    )

    def step(self) -> list[RunningTree]:
        """Run hooks, commit, and tick every tree whose deadline has come; returns them."""
        now = self.clock.now()
        for hook in self.hooks:
            try:
                hook(now)
            except Exception as error:  # a broken hook (scenario, reload, poller) is reported
                self.hook_errors += 1
                _log.exception("scheduler hook %r failed: %s", hook, error)
        self._listen_for_wake_keys()  # a hook may have reloaded a tree
        self.blackboard.commit()
        changed = self.blackboard.take_changed()
        for tree in self.trees:
            if changed.intersection(tree.definition.wake_on):  # resting or in a round
                tree.woken = True
        due = sorted(
            (
                tree
                for tree in self.trees
                if tree.next_deadline_s <= now + 1e-9 or _may_wake(tree, now)
            ),
            key=lambda tree: -tree.priority,  # stable: one priority keeps the added order
        )
        ticked = []
        for tree in due:
            if tree.paused or (tree.resting and not tree.woken):  # its deadlines go by
                tree.period_index = math.floor((now - tree.origin_s) / tree.period_s)
                while tree.next_deadline_s <= now + 1e-9:
                    tree.period_index += 1
                continue
            if tree.next_deadline_s > now + 1e-9:  # woken between deadlines: a new grid
                tree.origin_s, tree.period_index = now, 0
            self._tick(tree)
            ticked.append(tree)
        return ticked

    def _tick(self, tree: RunningTree) -> None:
        now = self.clock.now()  # hooks and earlier trees of this step count as lateness
        lateness = now - tree.next_deadline_s
        fresh = tree.status != py_trees.common.Status.RUNNING  # a round starts: sees it all
        if fresh and tree.tries_again:  # only a tree that tries again remembers where it began
            tree.events.round_starts()
        started = self._measure()
        try:
            tree.tree.tick()
        except Exception as error:  # composites are py_trees' own; keep the robot alive
            tree.stats.errors += 1
            _log.error("%s: tick failed: %s: %s", tree.name, type(error).__name__, error)
        tree.stats.record(self._measure() - started, max(0.0, lateness))
        status = tree.status
        if status == py_trees.common.Status.FAILURE:  # gave up half-way: nothing left raised
            tree.context.actions.settle(lights=False)  # a timed light goes out by itself
            tree.retrying = False
            tree.events.round_ends()
        elif status == py_trees.common.Status.SUCCESS:  # done as the tree meant
            tree.context.actions.forget()
            tree.retrying = False
            tree.events.round_ends()
        for observer in self.after_tick:
            try:
                observer(tree)
            except Exception as error:  # a view or recorder must never stop the robot
                self.hook_errors += 1
                _log.exception("after-tick observer %r failed: %s", observer, error)
        tree.period_index += 1
        tree.last_tick_s = now
        tree.woken = tree.woken and not fresh  # what came during a round wakes the next one
        # it waits once a tick finds nothing to do (FAILURE: its condition not met); after a
        # round that acted (SUCCESS) it ticks once more, so its nodes say they wait again
        waits = status == py_trees.common.Status.FAILURE and not tree.retrying
        if tree.definition.wake_on and waits and not tree.woken:
            tree.woken = tree.events.unread()  # one event a round: the next one, next
        tree.resting = bool(tree.definition.wake_on) and waits and not tree.woken
        if tree.next_deadline_s <= now:
            behind = math.floor((now - tree.origin_s) / tree.period_s) + 1
            tree.stats.skipped += behind - tree.period_index
            tree.period_index = behind


def _may_wake(tree: RunningTree, now: float) -> bool:
    """A woken tree whose rate lets it tick now (a period since its last tick)."""
    return tree.woken and not tree.paused and now - tree.last_tick_s >= tree.period_s - 1e-9
