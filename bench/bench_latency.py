"""Sensor -> action latency on the simulated vest in real time, and on-request sensor answers.

Run: ``.venv/bin/python bench/bench_latency.py`` (``--events N``, ``--help``); about 200 s.

The robot is built as ``vest run`` builds it without ``--fast``, by the composition root
(``build_session``): every tree in trees/ on a ``RealClock``, the simulated vest of
examples/robots/sim.yaml (register-level chips behind simulated buses) with one worker
thread per bus and one thread per poller, the hardware hooks (LED timer) and hot reload,
simulated speech with realistic durations. The scheduler runs on its own thread.

Three kinds of events, each changing the ``World`` at random moments from a thread (as
a person would; a scenario hook would only change it at the scheduler's wake-ups, which
are the trees' deadlines, and so would always hit the same phase):

- squeeze -> Say: both force pads to 6 N; the ``hug`` tree says its phrase;
- pat -> Say: a hand comes onto one touch pad (a different one each time): a pat event;
  ``touch_thanks`` says thanks;
- obstacle -> MoveServo: something at 500 mm on the left, then (next event) on the right,
  nothing in between; ``tracking`` turns the neck toward it.

Squeezes and pats take turns on one thread: both answers need the speaker, and one voice
at a time means a pat during a hug is let go (touch_thanks has the lower priority), which
would be turn-taking, not latency. Obstacles run beside them (the neck is no one else's).

Latency is measured from the clock time right after the world change was applied (the
chips hold the new state from then on) to the matching action on the session stream (the
``ActionStarted``'s ``t_s``, the clock time of the service call). After each action the
world goes back to rest, the driver waits until the tree is idle again (not running,
every ``Cooldown`` over) and the release has had time to be sensed (one poll period + one
tree period), then a random pause of 0..100 ms, so each event lands at a random phase of
polls and ticks.

To fit many events in a bounded run, the trees are loaded with a profile of short rests
(``hug_rest_s`` and ``thanks_rest_s`` 0.1 s instead of 10 s and 3 s); the trees themselves
are unchanged. The hug's LEDs stay lit 2 s, so a hug takes about 2.2 s: ``--events N`` is
the number of hugs and of pats (each after the other), and obstacles go on until they are
done (they get more).

The events are measured twice in one run: with the trees as shipped, whose ``wake_on:``
ticks a tree as soon as its key changes (issue 24's target: p99 <= one poll period + 5 ms),
and with ``wake_on`` taken out, every tree ticking at its rate as before.

Target (issue 3): p99 <= one tree period + one poll period, from the tree's ``rate_hz``
and the device's ``rate_hz`` in sim.yaml. Baseline printed beside it: the latency floor of
the phases, half a poll period + half a tree period, the expected p50 when a change waits
on average half a period for the poll and half a period for the tick and nothing else
takes time.

Each latency is split, from instrumentation of the pollers (start and end of every poll)
and of the trees (start of every tick), into: change -> start of the poll that delivered
it; the poll itself (a VL53L0X measurement takes its 33 ms timing budget); poll end -> the
tree's tick (the blackboard commit waits for the scheduler); tick start -> the action.
A poller and a tree of the same rate keep a fixed phase for the whole run, so "poll end ->
tick" is nearly the same for every event: it is that phase. Hence the model printed at the
end of each such line: at this run's phase, p50 = half a poll period + the rest's p50, and
max = one poll period + the rest's p99. The phases themselves are printed too (when each
poller polls after the trees' deadlines). ``vest run`` phases the pollers on the trees'
first deadline (+0.0), each poll starting early by its longest recent duration, so its
reading is staged just before the tick; a poll that takes longer than that lead misses the
tick and its news waits a whole tree period.

``--align-polls MS`` is a what-if, not what ``vest run`` does: the scheduler starts first,
then every poller is phased so that its polls end MS ms before the trees' deadlines (its
duration measured by one read beforehand). Compare the two runs to see what the phase
costs.

On-request sensors (``HardwareSensors.read``, how ``ReadSensor`` reads them): the time
from the call (job submitted) to ``job.done()``, polled every 0.5 ms from the bench's
thread (the figures can be up to that much late). Temperature is one MCP9808 register read
(target <= 10 ms), ultrasound an SRF02 ranging: command, 66 ms on the clock, read
(target <= 100 ms). They are read while the events run (every poller busy on the same
I2C bus), then again with the poller threads stopped (an idle bus: the baseline).
"""

from __future__ import annotations

import argparse
import bisect
import dataclasses
import math
import os
import platform
import queue
import random
import statistics
import sys
import tempfile
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

from py_trees.common import Status

from engine.clock import Clock, stopwatch
from engine.composition.session_root import RunningSession, SessionPlan, build_session
from engine.drivers.srf02_registers import RANGING_TIME_S
from engine.hardware.config import RobotConfig
from engine.hardware.config_file import load_robot_config
from engine.hardware.robot_hardware import Hardware
from engine.hardware.sim_vest import SimVest
from engine.nodes.decorators import Cooldown
from engine.runtime.robot import Robot, load_behaviors
from engine.runtime.scheduler import RunningTree
from engine.runtime.stats import percentile
from engine.scenario.scenario_file import Scenario
from engine.scenario.world import World
from engine.session.events import ActionStarted, SessionEvent

ROOT = Path(__file__).resolve().parents[1]
TREES_DIR = ROOT / "trees"
DIALOGS_DIR = ROOT / "dialogs"
SIM_CONFIG = ROOT / "examples" / "robots" / "sim.yaml"
SHORT_RESTS = """\
profile: bench-short-rests
description: short rests between reactions, so that many events fit in a bounded run
params:
  hug_rest_s: 0.1
  thanks_rest_s: 0.1
"""
WAKE_MARGIN_S = 0.005
"""A tree that wakes on its key answers within one poll period and this (issue 24)."""
SQUEEZE_N = 6.0  # above every profile's hug threshold
OBSTACLE_MM = 500.0  # well within tracking's max_mm
JITTER_S = 0.1  # random pause before each event: at least the longest poll period
ACTION_TIMEOUT_S = 1.5  # an event without its action after this long counts as missed
IDLE_TIMEOUT_S = 6.0
SETTLE_MARGIN_S = 0.02
JOB_POLL_S = 0.0005
TEMPERATURE_TARGET_S = 0.010
ULTRASOUND_TARGET_S = 0.100


# -- the robot, as `vest run` wires it in real time ---------------------------------------------
class Instruments:
    """When every poll started and ended, every tree tick started, every scheduler step ran."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self.polls: dict[str, list[tuple[float, float]]] = {}
        self.ticks: dict[str, list[float]] = {}
        self.steps: list[float] = []
        self.actions: dict[str, queue.SimpleQueue[ActionStarted]] = {}

    def watch_poller(self, poller: Any) -> None:
        spans: list[tuple[float, float]] = []
        self.polls[poller.name] = spans
        poll_once = poller.poll_once  # PollerThreads calls poller.poll_once()
        now = self.clock.now

        def timed_poll() -> bool:
            started = now()
            try:
                return poll_once()
            finally:
                spans.append((started, now()))

        poller.poll_once = timed_poll

    def watch_tree(self, tree: RunningTree) -> None:
        starts: list[float] = []
        self.ticks[tree.name] = starts
        now = self.clock.now
        tree.tree.add_pre_tick_handler(lambda _: starts.append(now()))

    def step_hook(self, now_s: float) -> None:
        """The last hook: runs right before the scheduler commits the staged writes."""
        self.steps.append(self.clock.now())

    def on_event(self, event: SessionEvent) -> None:
        """A session reader: each action, by tree."""
        if isinstance(event, ActionStarted):
            self.actions.setdefault(event.tree, queue.SimpleQueue()).put(event)


@dataclass
class Rig:
    clock: Clock
    config: RobotConfig
    world: World
    vest: SimVest
    hardware: Hardware
    robot: Robot
    instruments: Instruments
    running: RunningSession
    scheduler_thread: threading.Thread | None = None

    def start(self, align_margin_s: float | None = None) -> None:
        """Every part, then the scheduler, as ``vest run`` starts them (the pollers phased
        on the trees' first deadline).

        With ``align_margin_s`` (``--align-polls``, not what ``vest run`` does): once the
        trees tick, each poller is phased again so that its polls end that long before
        the trees' deadlines (its duration measured by one read beforehand).
        """
        took_s = {}
        if align_margin_s is not None:
            for poller in self.hardware.pollers:
                started = stopwatch()
                poller.read_now()
                took_s[poller.name] = stopwatch() - started
        self.scheduler_thread = threading.Thread(
            target=self.running.run, args=(math.inf,), name="scheduler", daemon=True
        )
        self.scheduler_thread.start()
        if align_margin_s is not None:
            while not any(tree.stats.ticks for tree in self.robot.trees):
                self.clock.sleep(0.001)
            self.hardware.stop()
            origin_s = self.robot.trees[0].origin_s
            for poller in self.hardware.pollers:
                poller.origin_s = origin_s - took_s[poller.name] - align_margin_s
            self.hardware.start()

    def close(self) -> None:
        self.robot.scheduler.stop()
        if self.scheduler_thread is not None:
            self.scheduler_thread.join(5.0)
        self.running.close()


def build_rig(profile: Path, *, wake: bool = True) -> Rig:
    """The robot as vest run builds it (the composition root's ``build_session``, in real
    time, with hot reload); ``wake``: the trees' ``wake_on`` as shipped, else taken out
    (every tree ticks at its rate, as before issue 24)."""
    behaviors = load_behaviors([TREES_DIR], dialogs_dir=DIALOGS_DIR, profile=profile)
    if not wake:
        behaviors.trees[:] = [dataclasses.replace(tree, wake_on=()) for tree in behaviors.trees]
    config = load_robot_config(SIM_CONFIG)
    moved_here = Scenario(duration_s=math.inf, events=(), path=Path("(the bench moves it)"))
    running = build_session(SessionPlan(behaviors, config, moved_here))
    assembled = running.assembled
    robot, world, hardware, clock = (
        assembled.robot,
        assembled.world,
        assembled.hardware,
        assembled.clock,
    )
    assert assembled.vest is not None
    if hardware.startup_problems:
        running.close()
        raise SystemExit(f"the simulated vest did not start: {hardware.startup_problems}")
    instruments = Instruments(clock)
    running.gates.kept.subscribe(instruments, (ActionStarted.kind,))
    robot.scheduler.add_hook(instruments.step_hook)
    for poller in hardware.pollers:
        instruments.watch_poller(poller)
    for tree in robot.trees:
        instruments.watch_tree(tree)
    return Rig(clock, config, world, assembled.vest, hardware, robot, instruments, running)


# -- the events ----------------------------------------------------------------------------------
@dataclass
class Kind:
    """One kind of event: what changes in the world, and which tree's action answers it."""

    label: str
    tree: str
    action: str
    press: Callable[[World, int], str]
    """Change the world for event ``i``; returns the device whose poll senses it."""
    release: Callable[[World], None]


def _squeeze(world: World, index: int) -> str:
    world.force_n.update(left=SQUEEZE_N, right=SQUEEZE_N)
    world.changed("force")
    return "force"


def _unsqueeze(world: World) -> None:
    world.force_n.update(left=0.0, right=0.0)
    world.changed("force")


def _pat(world: World, index: int) -> str:
    world.touched[index % len(world.touched)] = True
    world.changed("touch")
    return "touch"


def _untouch(world: World) -> None:
    world.touched[:] = [False] * len(world.touched)
    world.changed("touch")


def _obstacle(world: World, index: int) -> str:
    side = ("left", "right")[index % 2]  # the neck turns each time: +30, -30, +30...
    world.range_mm[side] = OBSTACLE_MM
    world.changed("range")
    return f"range_{side}"


def _clear(world: World) -> None:
    for side in world.range_mm:
        world.range_mm[side] = None
    world.changed("range")


KINDS = (
    Kind("squeeze -> Say", "hug", "say", _squeeze, _unsqueeze),
    Kind("pat -> Say", "touch_thanks", "say", _pat, _untouch),
    Kind("obstacle -> MoveServo", "tracking", "servo", _obstacle, _clear),
)


TAKING_TURNS = ((KINDS[0], KINDS[1]), (KINDS[2],))
"""The kinds each driver plays, one after the other: squeezes and pats both want the
speaker, so they take turns; obstacles move the neck beside them."""


@dataclass
class Sample:
    kind: Kind
    changed_s: float
    device: str
    acted_s: float | None  # None: no action within ACTION_TIMEOUT_S


@dataclass
class Driver:
    """Plays its kinds of event one after the other, again and again, on its own thread."""

    kinds: tuple[Kind, ...]
    rig: Rig
    rng: random.Random
    settle_s: float
    samples: list[Sample] = field(default_factory=list)
    error: BaseException | None = None

    def of(self, kind: Kind) -> list[Sample]:
        return [sample for sample in self.samples if sample.kind is kind]

    def run(self, enough: Callable[[Driver], bool], deadline_s: float) -> None:
        try:
            self._run(enough, deadline_s)
        except BaseException as error:  # reported by the main thread
            self.error = error

    def _run(self, enough: Callable[[Driver], bool], deadline_s: float) -> None:
        clock, world = self.rig.clock, self.rig.world
        index = 0
        while not enough(self) and clock.now() < deadline_s:
            kind = self.kinds[index % len(self.kinds)]
            tree = self.rig.robot.scheduler.tree(kind.tree)
            actions = self.rig.instruments.actions.setdefault(kind.tree, queue.SimpleQueue())
            clock.sleep(self.rng.uniform(0.0, JITTER_S))
            while not actions.empty():  # anything said or done before this event
                actions.get_nowait()
            device = kind.press(world, index // len(self.kinds))
            changed_s = clock.now()
            acted_s = self._wait_action(kind, actions, changed_s + ACTION_TIMEOUT_S)
            kind.release(world)
            released_s = clock.now()
            self.samples.append(Sample(kind, changed_s, device, acted_s))
            self._wait_idle(tree, released_s + self.settle_s)
            index += 1

    def _wait_action(
        self, kind: Kind, actions: queue.SimpleQueue[ActionStarted], until_s: float
    ) -> float | None:
        clock = self.rig.clock
        while (left_s := until_s - clock.now()) > 0:
            try:
                started = actions.get(timeout=left_s)
            except queue.Empty:
                return None
            if started.action == kind.action:
                return started.t_s
        return None

    def _wait_idle(self, tree: RunningTree, not_before_s: float) -> None:
        """Until the tree is not running, its cooldowns are over, and ``not_before_s``."""
        clock = self.rig.clock
        give_up_s = clock.now() + IDLE_TIMEOUT_S
        while clock.now() < give_up_s:
            now_s = clock.now()
            root = tree.tree.root
            cooling = any(
                node.ready_at_s > now_s for node in root.iterate() if isinstance(node, Cooldown)
            )
            if now_s >= not_before_s and root.status != Status.RUNNING and not cooling:
                return
            clock.sleep(0.01)


# -- on-request sensors ---------------------------------------------------------------------------
def time_reads(rig: Rig, sensor: str, count: int, rng: random.Random) -> list[float]:
    """``count`` answer times (seconds) of ``read(sensor)``, job submitted -> done."""
    sensors = rig.hardware.sensors
    clock = rig.clock
    answers: list[float] = []
    for _ in range(count):
        clock.sleep(rng.uniform(0.005, 0.05))
        started = stopwatch()
        job = sensors.read(sensor)
        while not job.done():
            clock.sleep(JOB_POLL_S)
        answers.append(stopwatch() - started)
        if job.error() is not None:
            raise SystemExit(f"{sensor} read failed: {job.error()}")
    return answers


def read_both(rig: Rig, count: int, rng: random.Random) -> dict[str, list[float]]:
    """Temperature and ultrasound, interleaved: ``count`` answers each."""
    times: dict[str, list[float]] = {"temperature": [], "ultrasound": []}
    for _ in range(count):
        for sensor, values in times.items():
            values.extend(time_reads(rig, sensor, 1, rng))
    return times


# -- the report -----------------------------------------------------------------------------------
def ms(seconds: float) -> str:
    return f"{seconds * 1e3:.1f}"


@dataclass
class Split:
    """One latency cut at the poll that delivered the change and the tick that acted."""

    to_poll_s: float
    poll_s: float
    to_tick_s: float
    in_tick_s: float


def split(sample: Sample, tree: str, instruments: Instruments) -> Split | None:
    assert sample.acted_s is not None
    ticks = instruments.ticks[tree]
    tick_index = bisect.bisect_right(ticks, sample.acted_s) - 1
    if tick_index < 0:
        return None
    tick_s = ticks[tick_index]
    step_index = bisect.bisect_right(instruments.steps, tick_s) - 1
    if step_index < 0:
        return None
    step_s = instruments.steps[step_index]
    polls = instruments.polls[sample.device]
    ends = [end for _, end in polls]
    poll_index = bisect.bisect_right(ends, step_s) - 1
    if poll_index < 0:
        return None
    start_s, end_s = polls[poll_index]
    if end_s < sample.changed_s:  # that poll was over before the change: not the one
        return None
    return Split(
        start_s - sample.changed_s, end_s - start_s, tick_s - end_s, sample.acted_s - tick_s
    )


def report_events(
    rig: Rig, drivers: list[Driver], elapsed_s: float, align_ms: float | None
) -> bool:
    config = rig.config
    instruments = rig.instruments
    phasing = (
        "pollers started as vest run starts them"
        if align_ms is None
        else f"WHAT-IF: polls phased to end {align_ms:g} ms before the deadlines"
    )
    print(
        f"sensor -> action latency on the simulated vest, real time (RealClock, threaded "
        f"pollers; {phasing}): {len(KINDS)} kinds, squeezes and pats taking turns, obstacles "
        f"beside them, for {elapsed_s:.0f} s; "
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs"
    )
    print(
        f"  {'event':<23}{'tree':<20}{'device':<20}{'n':>4}{'p50':>7}{'p99':>7}{'max':>7}"
        f"{'floor p50':>11}{'target p99':>12}  verdict"
    )
    all_ok = True
    splits: dict[str, tuple[list[Split], float]] = {}
    for driver, kind in ((d, k) for d in drivers for k in d.kinds):
        samples = driver.of(kind)
        tree = rig.robot.scheduler.tree(kind.tree)
        devices = sorted({sample.device for sample in samples})
        poll_period_s = max(1.0 / float(config.device(name).rate_hz or 1.0) for name in devices)
        tree_period_s = tree.period_s
        if tree.definition.wake_on:  # ticked when the poll stages the change (issue 24)
            target_s, floor_s = poll_period_s + WAKE_MARGIN_S, poll_period_s / 2
        else:
            target_s, floor_s = tree_period_s + poll_period_s, poll_period_s / 2 + tree_period_s / 2
        latencies = [s.acted_s - s.changed_s for s in samples if s.acted_s is not None]
        missed = len(samples) - len(latencies)
        p99 = percentile(latencies, 0.99)
        ok = bool(latencies) and missed == 0 and p99 <= target_s
        all_ok = all_ok and ok
        device_text = devices[0] if len(devices) == 1 else "range_left/right"
        rates = f"{1 / poll_period_s:g} Hz"
        print(
            f"  {kind.label:<23}{f'{kind.tree} {1 / tree_period_s:g} Hz':<20}"
            f"{f'{device_text} {rates}':<20}{len(latencies):>4}"
            f"{ms(percentile(latencies, 0.5)):>7}{ms(p99):>7}{ms(max(latencies, default=0)):>7}"
            f"{ms(floor_s):>11}{'<= ' + ms(target_s):>12}  {'OK' if ok else 'OVER'}"
            + (f" ({missed} events without an action)" if missed else "")
        )
        splits[kind.label] = (
            [
                cut
                for sample in samples
                if sample.acted_s is not None
                and (cut := split(sample, kind.tree, instruments)) is not None
            ],
            poll_period_s,
        )
    print("  (ms; p50/p99 by nearest rank; floor p50 = half a poll period + half a tree period)")
    print(
        "  where the time goes, p50 / p99 ms: change -> poll start | poll | poll end -> tick "
        "| tick -> action   => at this run's phase: p50, max"
    )
    for label, (cuts, poll_period_s) in splits.items():
        if not cuts:
            print(f"  {label:<23}(no event could be cut)")
            continue
        parts = [
            [c.to_poll_s for c in cuts],
            [c.poll_s for c in cuts],
            [c.to_tick_s for c in cuts],
            [c.in_tick_s for c in cuts],
        ]
        text = " | ".join(
            f"{ms(percentile(p, 0.5)):>5} / {ms(percentile(p, 0.99)):<5}" for p in parts
        )
        # the wait for the poll is uniform over one poll period; the rest is nearly fixed
        rest_p50 = sum(percentile(p, 0.5) for p in parts[1:])
        rest_p99 = sum(percentile(p, 0.99) for p in parts[1:])
        expected = f"{ms(poll_period_s / 2 + rest_p50)}, {ms(poll_period_s + rest_p99)}"
        print(f"  {label:<23}{text}  => {expected}  ({len(cuts)} cut)")
    return all_ok


def report_reads(
    busy: dict[str, list[float]], idle: dict[str, list[float]], ranging_s: float
) -> bool:
    print(
        f"on-request sensors (HardwareSensors.read: job submitted -> done, done() polled every "
        f"{JOB_POLL_S * 1e3:g} ms):"
    )
    print(
        f"  {'sensor':<13}{'n':>4}{'p50':>7}{'p99':>7}{'max':>7}   "
        f"{'idle bus p50/p99':<18}{'floor':>7}{'target':>9}  verdict"
    )
    all_ok = True
    for sensor, target_s, floor in (
        ("temperature", TEMPERATURE_TARGET_S, "-"),
        ("ultrasound", ULTRASOUND_TARGET_S, ms(ranging_s)),
    ):
        values = busy[sensor]
        p99 = percentile(values, 0.99)
        ok = p99 <= target_s
        all_ok = all_ok and ok
        quiet = idle[sensor]
        quiet_text = f"{ms(percentile(quiet, 0.5))} / {ms(percentile(quiet, 0.99))}"
        print(
            f"  {sensor:<13}{len(values):>4}{ms(percentile(values, 0.5)):>7}{ms(p99):>7}"
            f"{ms(max(values)):>7}   {quiet_text:<18}{floor:>7}{'<= ' + ms(target_s):>9}  "
            f"{'OK' if ok else 'OVER'}"
        )
    print(
        "  (ms; read while every poller runs on the same I2C bus; idle bus: poller threads "
        "stopped; floor: the SRF02's ranging time)"
    )
    return all_ok


def print_phases(rig: Rig) -> None:
    """Each poller's phase against the trees' deadlines (fixed for the run)."""
    origin_s = rig.robot.trees[0].origin_s
    parts = []
    for poller in rig.hardware.pollers:
        if poller.origin_s is None:
            continue
        spans = rig.instruments.polls.get(poller.name, [])
        took = statistics.median(end - start for start, end in spans) if spans else 0.0
        phase_s = (poller.origin_s - origin_s) % poller.period_s
        parts.append(f"{poller.name} +{ms(phase_s)} (poll {ms(took)})")
    print(
        "  poll phases after the trees' deadlines, ms (a poll's median duration): "
        + ", ".join(parts)
    )


# -- main -----------------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--events",
        type=int,
        default=30,
        help="hugs (~2.2 s each) and pats, taking turns; obstacles run meanwhile (default 30)",
    )
    parser.add_argument(
        "--reads", type=int, default=50, help="temperature and ultrasound reads each (default 50)"
    )
    parser.add_argument("--seed", type=int, default=3, help="random pauses (default 3)")
    parser.add_argument(
        "--align-polls",
        type=float,
        default=None,
        metavar="MS",
        help="phase every poller so that its polls end MS ms before the trees' deadlines "
        "(a what-if: vest run does not do this)",
    )
    parser.add_argument("--strict", action="store_true", help="exit 1 when a target is missed")
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.events, args.reads = 2, 3
    if args.events < 1 or args.reads < 1:
        parser.error("--events and --reads must be at least 1")

    events_ok = True
    for wake in (True, False):  # one after the other, in one run
        events_ok = measure_events(args, wake) and events_ok
    return 1 if args.strict and not events_ok else 0


def measure_events(args: argparse.Namespace, wake: bool) -> bool:
    """The events (and, with the shipped trees, the on-request reads) on one robot."""
    with tempfile.TemporaryDirectory() as folder:
        profile = Path(folder) / "short_rests.yaml"
        profile.write_text(SHORT_RESTS)
        rig = build_rig(profile, wake=wake)
    try:
        rig.start(None if args.align_polls is None else args.align_polls / 1e3)
        clock = rig.clock
        rng = random.Random(args.seed)
        # a release is sensed within one poll period and one tree period
        slowest_poll_s = max(poller.period_s for poller in rig.hardware.pollers)
        drivers = [
            Driver(
                kinds,
                rig,
                random.Random(rng.random()),
                settle_s=slowest_poll_s
                + max(rig.robot.scheduler.tree(kind.tree).period_s for kind in kinds)
                + SETTLE_MARGIN_S,
            )
            for kinds in TAKING_TURNS
        ]

        def enough(_: Driver) -> bool:
            return all(len(d.of(k)) >= args.events for d in drivers for k in d.kinds)

        started = clock.now()
        deadline_s = started + 5.0 + args.events * 6.0
        threads = [
            threading.Thread(
                target=driver.run,
                args=(enough, deadline_s),
                name=f"driver-{driver.kinds[0].tree}",
                daemon=True,
            )
            for driver in drivers
        ]
        for thread in threads:
            thread.start()
        busy = read_both(rig, args.reads, random.Random(rng.random())) if wake else {}
        for thread in threads:
            thread.join()
        elapsed_s = clock.now() - started
        for driver in drivers:
            if driver.error is not None:
                raise driver.error
        rig.hardware.stop()  # poller threads stopped: the bus is idle but for the reads
        idle = read_both(rig, args.reads, random.Random(rng.random())) if wake else {}
    finally:
        rig.close()
    shipped = "the trees as shipped (wake_on)" if wake else "every tree at its rate (no wake_on)"
    print(f"== {shipped}")
    events_ok = report_events(rig, drivers, elapsed_s, args.align_polls)
    print_phases(rig)
    if not wake:
        return events_ok
    return report_reads(busy, idle, RANGING_TIME_S) and events_ok


if __name__ == "__main__":
    sys.exit(main())
