"""How late the scheduler ticks every tree in real time, against loops that only sleep.

Run: ``.venv/bin/python bench/bench_scheduler.py`` (``--seconds N``, ``--help``).

Three phases in one run, on the machine's monotonic clock:

- engine: every tree in trees/ built by ``load_behaviors`` into a ``Robot`` on a
  ``RealClock``, the demo scenario (examples/scenarios/demo.yaml) played by a
  ``ScenarioPlayer`` hook and the hot-reload hook installed, as ``vest run`` does in real
  time; the ``Scheduler`` runs for ``--seconds``. Its own statistics give per tree the
  lateness (how long after the deadline the scheduler woke up to tick it) and the tick
  duration. A pre-tick handler on each tree also records when that tree's tick really
  began ("start late"): after the hooks, the blackboard commit and the trees ticked before
  it at the same deadline.
- baseline time.sleep: a bare loop with the same trees' rates and the same drift-free
  deadlines (origin + k * period) that sleeps with ``time.sleep`` and does nothing else.
- baseline clock wait: the same loop sleeping with ``RealClock.sleep_until(deadline,
  stop)``, a wait on a stop event that nobody sets: what the scheduler itself sleeps with.

Each baseline runs half its time before the engine phase and half after, so a change in
the machine's load during the run hits both. The baselines' lateness is the operating
system's (timer slack, scheduling, other processes); what the engine adds on top is its
own. All figures in milliseconds; p50/p99 by nearest rank.
"""

from __future__ import annotations

import argparse
import gc
import os
import platform
import sys
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import RealClock, stopwatch
from engine.hardware.config_file import load_robot_config
from engine.hardware.touch_pads import name_scenario_pads
from engine.runtime.reload import TreeReloader
from engine.runtime.robot import Robot, load_behaviors
from engine.runtime.scheduler import RunningTree
from engine.runtime.stats import TickStats, percentile
from engine.scenario.player import ScenarioPlayer
from engine.scenario.scenario_file import load_scenario
from engine.scenario.world import BlackboardSenses, World
from engine.services.simulated import simulated_services

ROOT = Path(__file__).resolve().parents[1]
TREES_DIR = ROOT / "trees"
DIALOGS_DIR = ROOT / "dialogs"
SCENARIO = ROOT / "examples" / "scenarios" / "demo.yaml"
SIM_CONFIG = ROOT / "examples" / "robots" / "sim.yaml"


class Row:
    """Lateness (and, for the engine, start lateness and durations) of one tree, seconds."""

    def __init__(self, name: str, rate_hz: float) -> None:
        self.name = name
        self.rate_hz = rate_hz
        self.stats = TickStats()
        self.start_late_s: list[float] = []

    @property
    def lateness_s(self) -> list[float]:
        return list(self.stats.lateness_s)

    @property
    def durations_s(self) -> list[float]:
        return list(self.stats.durations_s)


class EngineRun:
    """Every tree on the demo scenario in real time, built as ``vest run`` builds them."""

    def __init__(self) -> None:
        behaviors = load_behaviors([TREES_DIR], dialogs_dir=DIALOGS_DIR)
        self.scenario = load_scenario(SCENARIO)
        # its touches name pads ("middle_back"): numbered as the simulated vest names them
        problems = name_scenario_pads(self.scenario.events, load_robot_config(SIM_CONFIG))
        if problems:
            raise SystemExit(f"{SCENARIO}: {problems[0]}")
        self.clock = RealClock()
        blackboard = Blackboard(default_catalogue(), self.clock)
        blackboard.reset()
        self.world = World()
        senses = BlackboardSenses(blackboard, self.world)
        self.world.add_listener(senses)
        senses.start()
        services = simulated_services(self.clock, readers=senses.readers(), realistic=True)
        self.node_errors: list[str] = []
        self.robot = Robot(
            behaviors,
            clock=self.clock,
            services=services,
            blackboard=blackboard,
            on_node_error=lambda tree, path, error: self.node_errors.append(path),
        )
        self.log = self.robot.action_log
        self.rows = [Row(tree.name, tree.definition.rate_hz) for tree in self.robot.trees]
        for tree, row in zip(self.robot.trees, self.rows, strict=True):
            tree.tree.add_pre_tick_handler(_start_recorder(tree, row, self.clock))
        self.behaviors = behaviors

    @property
    def offsets_s(self) -> list[float]:
        """Each tree's deadline origin after the first tree's (the scheduler sets them)."""
        first = min(tree.origin_s for tree in self.robot.trees)
        return [tree.origin_s - first for tree in self.robot.trees]

    def run(self, seconds: float) -> None:
        start_s = self.clock.now()
        scheduler = self.robot.scheduler
        scheduler.add_hook(ScenarioPlayer(self.scenario, self.world, start_s=start_s))
        scheduler.add_hook(TreeReloader(self.behaviors.loader, self.robot.trees, self.clock))
        scheduler.run(until_s=start_s + seconds)
        for tree, row in zip(self.robot.trees, self.rows, strict=True):
            row.stats = tree.stats

    def done(self) -> Counter[str]:
        """What the robot did: "tree: action" -> how many times."""
        return Counter(f"{record.tree}: {record.action}" for record in self.log.records)


def _start_recorder(tree: RunningTree, row: Row, clock: RealClock) -> Callable[[object], None]:
    def record(_: object) -> None:
        row.start_late_s.append(max(0.0, clock.now() - tree.next_deadline_s))

    return record


def time_sleep_until(deadline_s: float) -> None:
    delay = deadline_s - time.monotonic()
    if delay > 0:
        time.sleep(delay)


def run_baseline(
    rows: list[Row], offsets_s: list[float], seconds: float, sleep_until: Callable[[float], None]
) -> None:
    """Sleep until each drift-free deadline of ``rows``' rates and only record lateness.

    Tree k's deadlines are ``origin + offsets_s[k] + i * period``: the engine's own offsets.
    """
    periods = [1.0 / row.rate_hz for row in rows]
    indexes = [0] * len(rows)
    origin = time.monotonic()
    origins = [origin + offset for offset in offsets_s]
    end = origin + seconds
    while True:
        deadline = min(o + i * p for o, i, p in zip(origins, indexes, periods, strict=True))
        if deadline > end:
            break
        sleep_until(deadline)
        now = time.monotonic()
        for k, row in enumerate(rows):
            due = origins[k] + indexes[k] * periods[k]
            if due > now + 1e-9:
                continue
            row.stats.record(0.0, max(0.0, now - due))
            indexes[k] += 1
            if origins[k] + indexes[k] * periods[k] <= now:  # overslept whole periods
                behind = int((now - origins[k]) / periods[k]) + 1
                row.stats.skipped += behind - indexes[k]
                indexes[k] = behind


def _ms(values: list[float], fraction: float) -> str:
    return f"{percentile(values, fraction) * 1e3:.3f}" if values else "-"


def _max_ms(values: list[float]) -> str:
    return f"{max(values) * 1e3:.3f}" if values else "-"


def print_rows(title: str, rows: list[Row], *, engine: bool) -> None:
    print(title)
    header = (
        f"    {'tree':<15}{'Hz':>4}{'ticks':>7}{'skip':>5}{'late p50':>10}{'late p99':>10}"
        f"{'late max':>10}"
    )
    if engine:
        header += f"{'start p50':>11}{'start p99':>11}{'tick p50':>10}{'tick p99':>10}"
    print(header)
    pooled: list[float] = []
    for row in rows:
        late = row.lateness_s
        pooled.extend(late)
        line = (
            f"    {row.name:<15}{row.rate_hz:>4g}{row.stats.ticks:>7}{row.stats.skipped:>5}"
            f"{_ms(late, 0.5):>10}{_ms(late, 0.99):>10}{_max_ms(late):>10}"
        )
        if engine:
            line += (
                f"{_ms(row.start_late_s, 0.5):>11}{_ms(row.start_late_s, 0.99):>11}"
                f"{_ms(row.durations_s, 0.5):>10}{_ms(row.durations_s, 0.99):>10}"
            )
        print(line)
    print(
        f"    {'all deadlines':<19}{len(pooled):>7}{'':>5}{_ms(pooled, 0.5):>10}"
        f"{_ms(pooled, 0.99):>10}{_max_ms(pooled):>10}"
    )


def own_delay(row: Row) -> list[float]:
    """Per tick: when the tick began minus when the scheduler woke up (hooks, commit, and
    the trees ticked before it at the same wake-up)."""
    woke_s = row.lateness_s
    began_s = row.start_late_s[len(row.start_late_s) - len(woke_s) :]  # stats keep a window
    return [began - woke for began, woke in zip(began_s, woke_s, strict=True)]


def pooled(rows: list[Row], which: Callable[[Row], list[float]]) -> list[float]:
    return [value for row in rows for value in which(row)]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--seconds", type=float, default=10.0, help="real seconds the engine runs (default 10)"
    )
    parser.add_argument(
        "--baseline-seconds",
        type=float,
        default=None,
        help="real seconds of each baseline, split before and after the engine "
        "(default: --seconds)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.seconds, args.baseline_seconds = 2.0, 1.0
    if args.seconds <= 0:
        parser.error("--seconds must be above 0")
    baseline_s = args.seconds if args.baseline_seconds is None else args.baseline_seconds
    if baseline_s <= 0:
        parser.error("--baseline-seconds must be above 0")

    probe = EngineRun()  # the same trees in the same order, and the scheduler's offsets
    rates = [(row.name, row.rate_hz) for row in probe.rows]
    probe_offsets_s = probe.offsets_s
    del probe
    sleeping = [Row(name, rate) for name, rate in rates]
    waiting = [Row(name, rate) for name, rate in rates]
    clock = RealClock()
    never_set = clock.event()

    def clock_sleep_until(deadline_s: float) -> None:
        clock.sleep_until(deadline_s, never_set)

    gc.collect()
    started = stopwatch()
    run_baseline(sleeping, probe_offsets_s, baseline_s / 2, time_sleep_until)
    run_baseline(waiting, probe_offsets_s, baseline_s / 2, clock_sleep_until)
    engine = EngineRun()
    engine.run(args.seconds)
    engine_rows = engine.rows
    run_baseline(waiting, engine.offsets_s, baseline_s / 2, clock_sleep_until)
    run_baseline(sleeping, engine.offsets_s, baseline_s / 2, time_sleep_until)
    elapsed_s = stopwatch() - started

    print(
        f"scheduler lateness: {len(rates)} trees from trees/ on {SCENARIO.name} "
        f"({engine.scenario.duration_s:g} s long), engine {args.seconds:g} s, each baseline "
        f"{baseline_s:g} s (half before, half after), {elapsed_s:.1f} s in all; "
        f"Python {platform.python_version()}, {platform.system()}, {os.cpu_count()} CPUs; "
        "milliseconds"
    )
    print_rows(
        "  engine (Scheduler on RealClock, demo scenario, hot reload on)", engine_rows, engine=True
    )
    print_rows("  baseline: time.sleep until each deadline, nothing else", sleeping, engine=False)
    print_rows(
        "  baseline: RealClock.sleep_until on a stop event (the scheduler's wait), nothing else",
        waiting,
        engine=False,
    )

    def late(rows: list[Row]) -> list[float]:
        return pooled(rows, lambda row: row.lateness_s)

    summary = {
        "time.sleep baseline: the OS wakes a bare loop": late(sleeping),
        "clock-wait baseline: the same, with the engine's way to sleep": late(waiting),
        "engine: the scheduler woke up (its own statistics)": late(engine_rows),
        "engine: the tree's tick began": pooled(engine_rows, lambda row: row.start_late_s),
        "engine's own delay: tick began - woke up, same tick": pooled(engine_rows, own_delay),
    }
    print("  summary, all deadlines pooled:" + " " * 43 + "p50 ms    p99 ms    max ms")
    for what, values in summary.items():
        print(f"    {what:<70}{_ms(values, 0.5):>8}{_ms(values, 0.99):>10}{_max_ms(values):>10}")
    offsets = ", ".join(
        f"{row.name} +{offset * 1e3:.3f}"
        for row, offset in zip(engine_rows, engine.offsets_s, strict=True)
    )
    print(
        f"  deadline origins as Scheduler.add set them (ms after the first tree's; the "
        f"baselines use the same offsets): {offsets}"
    )
    first = [row.lateness_s[0] * 1e3 for row in engine_rows if row.lateness_s]
    if first and engine_rows[0].stats.ticks == len(engine_rows[0].lateness_s):
        print(
            f"  first tick of each tree late by {min(first):.3f}..{max(first):.3f} ms: "
            "Scheduler.add stamps each origin when the Robot is built, before run() starts "
            "(counted above)"
        )
    done = engine.done()
    did = ", ".join(f"{what} x{count}" for what, count in sorted(done.items())) or "nothing"
    print(f"  the robot did: {did}; node errors: {len(engine.node_errors)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
