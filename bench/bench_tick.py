"""The engine's tick against the same trees hand-built in bare py_trees.

Run: ``.venv/bin/python bench/bench_tick.py`` (``--help`` for options; bench/README.md
explains the output).

Two trees from trees/ (hug, dialog), each built three times and ticked on its own virtual
clock with its own simulated services:

- engine: the YAML file loaded by the engine (TreeLoader, then TreeDefinition.build with a
  TreeContext as engine/testing/harness.py does), the engine's Blackboard, services
  reached through TreeActions (which records every call);
- bare: the same tree written by hand in py_trees 2.6: the same composites with the same
  options, py_trees' own CheckBlackboardVariableValue with a ComparisonExpression for the
  force checks, and small hand-written py_trees leaves for Cooldown, SetLed, Say, OnEvent
  and Reply that call the same simulated services directly and read and write the same
  blackboard keys through py_trees blackboard clients;
- lean: bare with hand-written checks, and leaves that tick the way the engine's Leaf does
  (without py_trees' per-tick debug message), to show the engine's cost on equal terms.

Each tree runs two workloads: idle (nobody touches or speaks: the first condition fails)
and active (both forces over the threshold, so the Sequence runs through the Cooldown and
lights and speaks every 12 s of tree time; for dialog, an utterance before every tick,
answered at once). The sides take turns in interleaved rounds (the order rotates each
round) so that drift in the machine's speed hits all alike; each side keeps its own copy
of the blackboard, swapped in for its turn. A round times blocks of one workload cycle each
(the time spent in ``BehaviourTree.tick()`` only; world changes and the clock are outside
the timing); the figure is the median over rounds of each round's median block, in
microseconds per tick. Afterwards the sides must have said and lit exactly the same things.

Target (DESIGN.md, performance): engine tick <= 1.25 x the bare py_trees tick.
``--profile`` adds cProfile tables of every side and workload.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import operator
import os
import platform
import pstats
import statistics
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

import py_trees
from py_trees.common import ComparisonExpression, ParallelPolicy, Status

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.blackboard.events import EventLog
from engine.clock import VirtualClock, stopwatch
from engine.dialogs.library import DialogLibrary
from engine.dialogs.model import Dialog
from engine.loader.tree_file import TreeLoader
from engine.nodes.context import TreeContext
from engine.nodes.registry import default_registry
from engine.scenario.world import BlackboardSenses, World
from engine.services.actions import ActionLog, TreeActions
from engine.services.interfaces import Services
from engine.services.jobs import Job
from engine.services.simulated import simulated_services

ROOT = Path(__file__).resolve().parents[1]
TARGET_RATIO = 1.25
TREES_DIR = ROOT / "trees"
DIALOGS_DIR = ROOT / "dialogs"
_STORAGE = py_trees.blackboard.Blackboard.storage

FORCE_LEFT = "/sensors/force/left_n"
FORCE_RIGHT = "/sensors/force/right_n"
HEARD = "/speech/heard"
HEARD_VAR = "/vars/dialog_heard"
SENSOR_KEYS = ("/sensors/temperature/c", "/sensors/temperature/f", "/sensors/ultrasound/cm")
# what the hug tree's parameters say in trees/hug.yaml (checked against the file below)
HUG_THRESHOLD_N = 3.0
HUG_REST_S = 10.0
HUG_COLOR = "pink"
HUG_LED_S = 2.0
HUG_PHRASE = "I love hugs!"
HUG_VOLUME = 0.8
SQUEEZE_N = 6.0
UTTERANCES = (
    "what is the temperature",
    "what's your name?",
    "which colour do you like",
    "can you fly",  # no rule: the fallback answer
)


# -- the bare py_trees side: what a developer writes without the engine -------------------
class BareCooldown(py_trees.decorators.Decorator):
    """After the child succeeds, FAILURE for ``seconds`` without ticking the child."""

    def __init__(
        self, name: str, child: py_trees.behaviour.Behaviour, seconds: float, clock: VirtualClock
    ) -> None:
        super().__init__(name=name, child=child)
        self.seconds = seconds
        self.clock = clock
        self.ready_at_s = float("-inf")

    def tick(self) -> Any:
        if self.status != Status.RUNNING and self.clock.now() < self.ready_at_s:
            self.stop(Status.FAILURE)
            yield self
            return
        yield from super().tick()

    def update(self) -> Status:
        status = self.decorated.status
        if status == Status.SUCCESS:
            self.ready_at_s = self.clock.now() + self.seconds
        return status


class BareJobAction(py_trees.behaviour.Behaviour):
    """Starts a service job in initialise(); RUNNING until it is done, then its outcome."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.job: Job | None = None

    def start(self) -> Job:
        raise NotImplementedError

    def initialise(self) -> None:
        self.job = self.start()

    def update(self) -> Status:
        if self.job is None:
            return Status.FAILURE
        if not self.job.done():
            return Status.RUNNING
        return Status.FAILURE if self.job.error() is not None else Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.job is not None and not self.job.done():
            self.job.cancel()


class BareSay(BareJobAction):
    def __init__(self, name: str, services: Services, text: str, volume: float | None) -> None:
        super().__init__(name)
        self.services, self.text, self.volume = services, text, volume

    def start(self) -> Job:
        return self.services.speech.say(self.text, volume=self.volume)


class BareSetLed(BareJobAction):
    def __init__(self, name: str, services: Services, color: str, seconds: float) -> None:
        super().__init__(name)
        self.services, self.color, self.seconds = services, color, seconds

    def start(self) -> Job:
        return self.services.leds.set_color(self.color, seconds=self.seconds)


class BareAbove(py_trees.behaviour.Behaviour):
    """A hand-written check: SUCCESS when ``key`` holds a value above ``threshold``."""

    def __init__(self, name: str, key: str, threshold: float) -> None:
        super().__init__(name)
        self.key, self.threshold = key, threshold
        self.blackboard = self.attach_blackboard_client(name=name)
        self.blackboard.register_key(key, access=py_trees.common.Access.READ)

    def update(self) -> Status:
        try:
            value = self.blackboard.get(self.key)
        except KeyError:
            return Status.FAILURE
        return Status.SUCCESS if value > self.threshold else Status.FAILURE


class BareOnEvent(py_trees.behaviour.Behaviour):
    """SUCCESS once per new event on ``key`` (an EventLog), saving its value to ``save_as``."""

    def __init__(self, name: str, key: str, save_as: str) -> None:
        super().__init__(name)
        self.key, self.save_as = key, save_as
        self.blackboard = self.attach_blackboard_client(name=name)
        self.blackboard.register_key(key, access=py_trees.common.Access.READ)
        self.blackboard.register_key(save_as, access=py_trees.common.Access.WRITE)
        log = _STORAGE.get(key)
        self.handled_seq = log.last_seq if isinstance(log, EventLog) else 0

    def update(self) -> Status:
        try:
            log = self.blackboard.get(self.key)
        except KeyError:
            return Status.FAILURE
        if log.last_seq <= self.handled_seq:
            return Status.FAILURE
        event = log.after(self.handled_seq)[0]
        self.handled_seq = event.seq
        self.blackboard.set(self.save_as, event.value)
        return Status.SUCCESS


class BareReply(py_trees.behaviour.Behaviour):
    """Match what was heard against the same dialog, read a sensor if asked, say the answer."""

    def __init__(self, name: str, heard: str, dialog: Dialog, services: Services) -> None:
        super().__init__(name)
        self.heard, self.dialog, self.services = heard, dialog, services
        self.blackboard = self.attach_blackboard_client(name=name)
        self.blackboard.register_key(heard, access=py_trees.common.Access.READ)
        for key in SENSOR_KEYS:
            self.blackboard.register_key(key, access=py_trees.common.Access.WRITE)
        self.job: Job | None = None
        self.answer: Any = None
        self.reading = False

    def read(self, key: str) -> Any:
        try:
            return self.blackboard.get(key)
        except KeyError:
            return None

    def initialise(self) -> None:
        self.job, self.answer, self.reading = None, None, False
        heard = self.read(self.heard)
        match = self.dialog.match(str(heard)) if heard else None
        if match is None:
            if self.dialog.fallback is not None:
                self.job = self.services.speech.say(self.dialog.fallback.fill(self.read))
            return
        self.answer = match.rule.answer
        if match.rule.read:
            self.reading = True
            self.job = self.services.sensors.read(match.rule.read)
        else:
            self.job = self.services.speech.say(self.answer.fill(self.read))

    def update(self) -> Status:
        if self.job is None:
            return Status.FAILURE
        if not self.job.done():
            return Status.RUNNING
        if self.job.error() is not None:
            return Status.FAILURE
        if self.reading:
            self.reading = False
            for key, value in (self.job.result() or {}).items():
                self.blackboard.set(key, value)
            self.job = self.services.speech.say(self.answer.fill(self.read))
            return self.update()
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if new_status == Status.INVALID and self.job is not None and not self.job.done():
            self.job.cancel()


class LeanTick:
    """A leaf tick without py_trees' per-tick debug message and status check.

    py_trees' ``Behaviour.tick`` formats a debug log line and builds ``list(Status)`` on
    every tick; the engine's ``Leaf.tick`` does neither. The lean leaves tick like the
    engine's (less its exception guard), to show what the engine costs on equal terms.
    """

    def tick(self: Any) -> Any:
        if self.status != Status.RUNNING:
            self.initialise()
        new_status = self.update()
        if new_status != Status.RUNNING:
            self.stop(new_status)
        self.status = new_status
        yield self


class LeanSay(LeanTick, BareSay):
    pass


class LeanSetLed(LeanTick, BareSetLed):
    pass


class LeanAbove(LeanTick, BareAbove):
    pass


class LeanOnEvent(LeanTick, BareOnEvent):
    pass


class LeanReply(LeanTick, BareReply):
    pass


def bare_hug(clock: VirtualClock, services: Services, *, lean: bool) -> Any:
    """trees/hug.yaml by hand: py_trees' CheckBlackboardVariableValue, or ``lean`` leaves."""
    checks: list[py_trees.behaviour.Behaviour] = []
    for key in (FORCE_LEFT, FORCE_RIGHT):
        if lean:
            checks.append(LeanAbove("Check", key, HUG_THRESHOLD_N))
        else:
            expression = ComparisonExpression(key, HUG_THRESHOLD_N, operator.gt)
            checks.append(py_trees.behaviours.CheckBlackboardVariableValue("Check", expression))
    set_led, say = (LeanSetLed, LeanSay) if lean else (BareSetLed, BareSay)
    show = py_trees.composites.Parallel(
        "Parallel",
        policy=ParallelPolicy.SuccessOnAll(synchronise=True),
        children=[
            set_led("SetLed", services, HUG_COLOR, HUG_LED_S),
            say("Say", services, HUG_PHRASE, HUG_VOLUME),
        ],
    )
    root = py_trees.composites.Sequence(
        "Sequence",
        memory=True,
        children=[*checks, BareCooldown("Cooldown", show, HUG_REST_S, clock)],
    )
    return py_trees.trees.BehaviourTree(root)


def bare_dialog(services: Services, dialog: Dialog, *, lean: bool) -> Any:
    """trees/dialog.yaml by hand."""
    on_event, reply = (LeanOnEvent, LeanReply) if lean else (BareOnEvent, BareReply)
    root = py_trees.composites.Sequence(
        "Sequence",
        memory=True,
        children=[
            on_event("OnEvent", HEARD, HEARD_VAR),
            reply("Reply", HEARD_VAR, dialog, services),
        ],
    )
    return py_trees.trees.BehaviourTree(root)


# -- both sides: a tree, its clock, its copy of the blackboard, its world ------------------
@dataclass
class Side:
    """One built tree, ticked on its own virtual clock with its own blackboard contents."""

    label: str
    tree: Any
    clock: VirtualClock
    period_s: float
    services: Services
    set_value: Callable[[str, Any], None]
    emit: Callable[[str, Any], None]
    errors: list[str] = field(default_factory=list)
    saved: dict[str, Any] = field(default_factory=dict)
    ticks: int = 0

    def enter(self) -> None:
        """Put this side's blackboard contents in py_trees' (process-wide) storage (the
        bare py_trees side reads it; the engine's side reads its own Blackboard)."""
        _STORAGE.clear()
        _STORAGE.update(self.saved)

    def leave(self) -> None:
        self.saved = dict(_STORAGE)

    def said(self) -> list[Any]:
        return list(self.services.speech.calls)  # type: ignore[attr-defined]

    def lit(self) -> list[Any]:
        return list(self.services.leds.calls)  # type: ignore[attr-defined]


@dataclass(frozen=True)
class Workload:
    """What the world does: ``setup`` once, ``before_tick`` before each tick (untimed)."""

    name: str
    block_ticks: int  # one cycle of the workload
    setup: Callable[[Side], None]
    before_tick: Callable[[Side], None] | None = None
    share: float = 1.0  # of --ticks per round: costly workloads run fewer ticks

    def blocks(self, ticks: int) -> int:
        """How many blocks make about ``ticks * share`` ticks (at least one)."""
        return max(1, round(ticks * self.share) // self.block_ticks)


def _squeezed(force_n: float) -> Callable[[Side], None]:
    def setup(side: Side) -> None:
        side.set_value(FORCE_LEFT, force_n)
        side.set_value(FORCE_RIGHT, force_n)

    return setup


def _old_utterance(side: Side) -> None:
    side.emit(HEARD, "hello")  # before the tree starts: never answered, but on the board


def _speak(side: Side) -> None:
    side.emit(HEARD, UTTERANCES[side.ticks % len(UTTERANCES)])


WORKLOADS = {
    # 20 Hz: idle ticks in blocks of 1 s; active: 240 ticks = 12 s = 2 s of LEDs + 10 s rest
    "hug": (Workload("idle", 20, _squeezed(0.0)), Workload("active", 240, _squeezed(SQUEEZE_N))),
    # 10 Hz: idle in blocks of 1 s; active: one utterance before every tick, 4 kinds
    "dialog": (
        Workload("idle", 10, _old_utterance),
        Workload("active", len(UTTERANCES), _old_utterance, _speak, share=0.125),
    ),
}


class Builder:
    """Builds the engine and bare versions of a tree, each fresh."""

    def __init__(self) -> None:
        self.catalogue = default_catalogue()
        self.dialogs = DialogLibrary.from_folder(DIALOGS_DIR, self.catalogue)
        self.loader = TreeLoader(default_registry(), self.catalogue, dialogs=self.dialogs)
        self.definitions = {
            name: self.loader.load(TREES_DIR / f"{name}.yaml") for name in WORKLOADS
        }
        self._check_hug_file()

    def _check_hug_file(self) -> None:
        """The bare hug must use the numbers in trees/hug.yaml; stop if someone changed them."""
        root = self.definitions["hug"].root
        checks, cooldown = root.children[:2], root.children[2]
        led, say = cooldown.children[0].children
        found = (
            checks[0].args["above"],
            checks[1].args["above"],
            cooldown.args["seconds"],
            led.args["color"],
            led.args["seconds"],
            str(say.args["text"]),
            say.args["volume"],
        )
        expected = (
            HUG_THRESHOLD_N,
            HUG_THRESHOLD_N,
            HUG_REST_S,
            HUG_COLOR,
            HUG_LED_S,
            HUG_PHRASE,
            HUG_VOLUME,
        )
        if found != expected:
            raise SystemExit(
                f"trees/hug.yaml changed: {found} != {expected}; update the "
                "bare tree in bench/bench_tick.py"
            )

    def engine(self, name: str, workload: Workload) -> Side:
        definition = self.definitions[name]
        clock = VirtualClock()
        blackboard = Blackboard(self.catalogue, clock)
        senses = BlackboardSenses(blackboard, World())
        services = simulated_services(clock, readers=senses.readers())
        errors: list[str] = []
        context = TreeContext(
            tree=definition.name,
            clock=clock,
            blackboard=blackboard,
            actions=TreeActions(services, clock, definition.name, ActionLog()),
            dialogs=self.dialogs,
            on_node_error=lambda tree, path, error: errors.append(f"{path}: {error}"),
        )
        side = Side(
            "engine",
            None,
            clock,
            1.0 / definition.rate_hz,
            services,
            blackboard.set,
            blackboard.emit,
            errors,
        )
        return self._started(side, workload, lambda: definition.build(context))

    def bare(self, name: str, workload: Workload, *, lean: bool = False) -> Side:
        definition = self.definitions[name]
        clock = VirtualClock()
        senses = BlackboardSenses(Blackboard(self.catalogue, clock), World())
        services = simulated_services(clock, readers=senses.readers())

        def set_value(key: str, value: Any) -> None:
            _STORAGE[key] = value

        def emit(key: str, value: Any) -> None:
            log = _STORAGE.get(key)
            log = log if isinstance(log, EventLog) else EventLog()
            _STORAGE[key] = log.appended(value, clock.now())

        if name == "hug":
            build = lambda: bare_hug(clock, services, lean=lean)  # noqa: E731
        else:
            dialog = self.dialogs.get("default")
            assert dialog is not None
            build = lambda: bare_dialog(services, dialog, lean=lean)  # noqa: E731
        label = "lean" if lean else "bare"
        side = Side(label, None, clock, 1.0 / definition.rate_hz, services, set_value, emit)
        return self._started(side, workload, build)

    @staticmethod
    def _started(side: Side, workload: Workload, build: Callable[[], Any]) -> Side:
        side.enter()
        workload.setup(side)
        side.tree = build()  # after setup: events already there are not reacted to
        side.leave()
        return side


def run_blocks(side: Side, workload: Workload, blocks: int) -> list[float]:
    """Tick ``blocks`` workload cycles; microseconds per tick of each block."""
    tick = side.tree.tick
    before = workload.before_tick
    per_tick_us = []
    side.enter()
    for _ in range(blocks):
        spent = 0.0
        for _ in range(workload.block_ticks):
            if before is not None:
                before(side)
            started = stopwatch()
            tick()
            spent += stopwatch() - started
            side.clock.advance(side.period_s)
            side.ticks += 1
        per_tick_us.append(spent * 1e6 / workload.block_ticks)
    side.leave()
    return per_tick_us


@dataclass
class Case:
    """One tree under one workload, with its sides and each side's per-round medians."""

    tree: str
    workload: Workload
    sides: dict[str, Side]
    round_us: dict[str, list[float]] = field(default_factory=dict)

    def median_us(self, label: str) -> float:
        return statistics.median(self.round_us[label])


def measure(cases: list[Case], rounds: int, ticks: int) -> None:
    for case in cases:
        case.round_us = {label: [] for label in case.sides}
        for side in case.sides.values():  # warm up
            run_blocks(side, case.workload, max(1, 100 // case.workload.block_ticks))
    for index in range(rounds):
        for case in cases:
            blocks = case.workload.blocks(ticks)
            labels = list(case.sides)
            shift = index % len(labels)
            for label in labels[shift:] + labels[:shift]:
                per_block = run_blocks(case.sides[label], case.workload, blocks)
                case.round_us[label].append(statistics.median(per_block))


def same_actions(case: Case) -> str:
    """Whether every side said and lit the same things (the trees behave alike)."""
    engine = case.sides["engine"]
    for label, side in case.sides.items():
        if label == "engine":
            continue
        if side.ticks != engine.ticks:
            return f"{label} ticked {side.ticks} times, engine {engine.ticks}"
        if side.said() != engine.said() or side.lit() != engine.lit():
            return (
                f"DIFFERENT: {label} said {len(side.said())} / lit {len(side.lit())}, "
                f"engine said {len(engine.said())} / lit {len(engine.lit())}"
            )
    said, lit = len(engine.said()), len(engine.lit())
    return f"same ({said} said, {lit} lit)"


def profile(case: Case, ticks: int, top: int) -> None:
    for label, side in case.sides.items():
        blocks = case.workload.blocks(ticks)
        profiler = cProfile.Profile()
        profiler.enable()
        run_blocks(side, case.workload, blocks)
        profiler.disable()
        out = io.StringIO()
        stats = pstats.Stats(profiler, stream=out)
        stats.sort_stats("tottime").print_stats(top)
        print(
            f"\n=== profile: {case.tree} {case.workload.name}, {label}, "
            f"{blocks * case.workload.block_ticks} ticks (sorted by own time) ==="
        )
        lines = out.getvalue().splitlines()
        start = next((i for i, line in enumerate(lines) if "ncalls" in line), 0)
        print("\n".join(lines[start:]).rstrip())


def print_table(cases: list[Case], reference: str, verdict_title: str) -> bool:
    """One row per tree and workload against the ``reference`` side; True if one is over."""
    print(
        f"  {'tree':<8}{'workload':<10}{reference + ' us/tick':>13}{'engine us/tick':>16}"
        f"{'engine-' + reference:>13}{'ratio':>8}  {verdict_title:<17}{'round ratios':>14}"
    )
    over = False
    for case in cases:
        reference_us, engine_us = case.median_us(reference), case.median_us("engine")
        ratio = engine_us / reference_us
        round_ratios = [
            e / r for e, r in zip(case.round_us["engine"], case.round_us[reference], strict=True)
        ]
        verdict = "OK" if ratio <= TARGET_RATIO else "OVER"
        over = over or verdict != "OK"
        print(
            f"  {case.tree:<8}{case.workload.name:<10}{reference_us:>13.2f}{engine_us:>16.2f}"
            f"{engine_us - reference_us:>+13.2f}{ratio:>7.2f}x  "
            f"{verdict if reference == 'bare' else '':<17}"
            f"{min(round_ratios):>6.2f}..{max(round_ratios):.2f}"
        )
    return over


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=21, help="interleaved rounds (default 21)")
    parser.add_argument(
        "--ticks",
        type=int,
        default=1200,
        help="ticks per side, round and workload (default 1200; dialog active: 1/8)",
    )
    parser.add_argument(
        "--profile",
        action="store_true",
        help="also print cProfile tables of each side and workload",
    )
    parser.add_argument("--top", type=int, default=25, help="rows per profile table (default 25)")
    parser.add_argument(
        "--strict", action="store_true", help="exit 1 when a ratio is over the target"
    )
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.rounds, args.ticks = 2, 60
    if args.rounds < 1 or args.ticks < 1:
        parser.error("--rounds and --ticks must be at least 1")

    Blackboard(default_catalogue(), VirtualClock()).reset()
    builder = Builder()
    cases = []
    for tree, workloads in WORKLOADS.items():
        for workload in workloads:
            sides = {
                "bare": builder.bare(tree, workload),
                "engine": builder.engine(tree, workload),
                "lean": builder.bare(tree, workload, lean=True),
            }
            cases.append(Case(tree, workload, sides))

    started = stopwatch()
    measure(cases, args.rounds, args.ticks)
    elapsed_s = stopwatch() - started

    print(
        f"engine tick vs bare py_trees {py_trees.version.__version__}: {args.rounds} interleaved "
        f"rounds of ~{args.ticks} ticks per side, {elapsed_s:.1f} s; Python "
        f"{platform.python_version()}, {os.cpu_count()} CPUs"
    )
    over = print_table(cases, "bare", "target <= " + format(TARGET_RATIO, "g") + "x")
    print("  the same trees with lean hand-written leaves (no py_trees debug line per leaf tick):")
    print_table(cases, "lean", "for scale")
    for case in cases:
        errors = [f"{label}: {e}" for label, s in case.sides.items() for e in s.errors]
        print(
            f"  actions {case.tree} {case.workload.name}: {same_actions(case)}"
            + (f"; NODE ERRORS: {errors[:3]}" if errors else "")
        )

    if args.profile:
        for case in cases:
            profile(case, args.ticks * 4, args.top)
    return 1 if args.strict and over else 0


if __name__ == "__main__":
    sys.exit(main())
