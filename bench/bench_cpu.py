"""CPU use of `vest run` in real time, every tree and poller running, as % of one core.

Run: ``.venv/bin/python bench/bench_cpu.py`` (``--seconds S``, ``--help``); about 20 s.

``vest run --duration S`` runs as a subprocess, exactly as a person starts it: every tree
in trees/, the demo scenario, in real time on the simulated vest (examples/robots/
sim.yaml: one worker thread per bus, one thread per poller, the Maestro emulator on a
pseudo-terminal). Its CPU time (user + system) comes from ``getrusage(RUSAGE_CHILDREN)``
around the subprocess; wall time from the bench's own stopwatch.

A run's CPU time includes start-up (Python, imports, loading and checking the trees,
building the hardware) and shutdown, which a long-running robot pays once. Two baselines
in the same run, each run ``--repeat`` times, half before and half after the long run
(medians), take them out:

- ``python -c "import engine.cli"``: the interpreter and the imports;
- ``vest run --duration 0.01``: the whole of ``vest run``'s start-up and shutdown with
  next to no running.

steady state = (CPU of the long run - CPU of the short run) / (wall of the long run - wall
of the short run). As a cross-check, the bench also reads the long run's
``/proc/PID/stat`` (utime + stime, clock ticks) every 0.25 s and reports the CPU used
while the scenario ran: from ``--skip`` seconds after vest run printed its timeline's
heading (start-up done: trees checked, speech models loaded, the voice warmed up) to the
last reading before the blank line that ends the timeline (shutdown follows), free of
start-up and shutdown by construction (Linux only).

There is no target in DESIGN.md for this figure: it is printed for the reader. What a
steady-state percentage means: the share of one core the robot needs, all threads
together, with the demo's events (touch, hug, wave, obstacle, speech) going on.

Then an idle robot (issue 24: trees that wake when something happens): ``vest run`` on a
scenario where nothing happens, with the shipped trees (their ``wake_on:``) and with the
same trees with ``wake_on:`` taken out (every tree ticks at its rate), one after the
other, each read inside the run from /proc as above. With ``--against FOLDER`` (a checkout
of an earlier commit, e.g. ``git worktree add /tmp/before 20d1990``, main before issue 24)
the same idle scenario also runs on that checkout's code (with this checkout's
interpreter and packages), interleaved with the others. Target (issue 24): an idle robot
spends at most half of what it did before issue 24. What it spends is mostly not the
trees' ticking (compare the first two lines) but the sensors' polling, the camera and the
microphone: the issue's range-sensor, camera-attention and noise-floor changes, which
``wake_on`` alone does not switch off, are what ``--against`` measures.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

from engine.clock import stopwatch

ROOT = Path(__file__).resolve().parents[1]
VEST = [sys.executable, "-c", "import sys; from engine.cli import main; sys.exit(main())"]
IMPORT_ONLY = [sys.executable, "-c", "import engine.cli"]
TIMELINE_LINE = re.compile(r"^\s*\d+\.\d+\s+(\S+)\s")  # "    3.10  hug   says ..."
SAMPLE_EVERY_S = 0.25
TICKS_PER_S = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


@dataclass
class Run:
    """One subprocess: its wall time, CPU time, and CPU readings taken while it ran."""

    wall_s: float
    user_s: float
    system_s: float
    readings: list[tuple[float, float]] = field(default_factory=list)
    """(seconds since start, CPU seconds so far) from /proc/PID/stat."""
    output: str = ""
    running: tuple[float, ...] = ()
    """When vest run's scenario began and ended (seconds since the start), as its output said."""

    @property
    def cpu_s(self) -> float:
        return self.user_s + self.system_s


def proc_cpu_s(pid: int) -> float | None:
    """utime + stime of a live process, in seconds (None off Linux or once it is gone)."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text[text.rindex(")") + 2 :].split()  # after "pid (comm) "
    return (int(fields[11]) + int(fields[12])) / TICKS_PER_S  # fields 14 and 15 of stat


def measure(command: list[str], *, sample: bool = False, cwd: Path = ROOT) -> Run:
    """Run ``command`` from ``cwd`` (the project folder); its CPU time from RUSAGE_CHILDREN."""
    with tempfile.TemporaryFile(mode="w+") as out:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = stopwatch()
        process = subprocess.Popen(command, cwd=cwd, stdout=out, stderr=subprocess.STDOUT)
        readings: list[tuple[float, float]] = []
        running: list[float] = []  # when the run began and ended, seconds since the start
        while process.poll() is None:
            if sample:
                cpu_s = proc_cpu_s(process.pid)
                if cpu_s is not None:
                    now = stopwatch() - started
                    readings.append((now, cpu_s))
                    running = _running_marks(out.fileno(), running, now)
            time.sleep(SAMPLE_EVERY_S if sample else 0.005)
        wall_s = stopwatch() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        out.seek(0)
        output = out.read()
    if process.returncode != 0:
        raise SystemExit(f"{' '.join(command)} exited with {process.returncode}:\n{output}")
    return Run(
        wall_s,
        after.ru_utime - before.ru_utime,
        after.ru_stime - before.ru_stime,
        readings,
        output,
        tuple(running),
    )


def _running_marks(output: int, marks: list[float], now: float) -> list[float]:
    """``marks`` with ``now`` added when vest run's output has just begun or ended its run.

    vest run prints its timeline's heading as the scenario starts (start-up done: models
    loaded, voice warmed up) and a blank line as it ends (shutdown follows).
    """
    if len(marks) == 2:
        return marks
    text = os.pread(output, 1 << 20, 0)  # leaves the file's offset, which the child shares
    lines = text.decode(errors="replace").splitlines()
    began = any(line.lstrip().startswith("t (s)") for line in lines)
    ended = began and "" in lines[[ln.lstrip().startswith("t (s)") for ln in lines].index(True) :]
    if len(marks) == 0 and began:
        marks = [now]
    if len(marks) == 1 and ended:
        marks = [*marks, now]
    return marks


def steady_window(run: Run, skip_s: float) -> tuple[float, float, float] | None:
    """(share of one core, from, to): what ``run`` used while its scenario ran (/proc readings).

    From ``skip_s`` seconds after the scenario began (after the process started when its
    output never said) to the last reading before the scenario ended; None if too short.
    """
    began = run.running[0] if run.running else 0.0
    ended = run.running[1] if len(run.running) == 2 else math.inf
    # the reading taken when the end showed in the output already holds some of the
    # shutdown (halting the trees, closing the pollers): the window stops before it
    window = [(t, cpu) for t, cpu in run.readings if began + skip_s <= t < ended]
    if len(window) < 2 or window[-1][0] <= window[0][0]:
        return None
    (t0, cpu0), (t1, cpu1) = window[0], window[-1]
    return (cpu1 - cpu0) / (t1 - t0), t0, t1


def idle_robot(seconds: float, skip_s: float, rounds: int, against: Path | None) -> None:
    """CPU of an idle robot with the shipped trees' wake_on and without it (and on the
    checkout ``against``)."""
    with tempfile.TemporaryDirectory() as folder:
        idle = Path(folder) / "idle.yaml"
        idle.write_text(f"description: nothing happens\nduration_s: {seconds:g}\nevents: []\n")
        ticking = Path(folder) / "trees"
        shutil.copytree(ROOT / "trees", ticking)
        for tree in ticking.rglob("*.yaml"):
            lines = tree.read_text().splitlines(keepends=True)
            tree.write_text("".join(ln for ln in lines if not ln.startswith("wake_on:")))
        ways = {
            "wake_on (as shipped)": [*VEST, "run", "--scenario", str(idle)],
            "every tree at its rate": [
                *VEST,
                "run",
                "--scenario",
                str(idle),
                "--trees",
                str(ticking),
            ],
        }
        folders = dict.fromkeys(ways, ROOT)
        if against is not None:
            name = f"{against.name} (--against)"
            ways[name] = [*VEST, "run", "--scenario", str(idle)]
            folders[name] = against
        shares: dict[str, list[float]] = {name: [] for name in ways}
        for _ in range(rounds):  # interleaved: a busy machine hurts all alike
            for name, command in ways.items():
                run = measure(command, sample=True, cwd=folders[name])
                steady = steady_window(run, skip_s)
                if steady is not None:
                    shares[name].append(steady[0])
    print(f"idle robot (a {seconds:g} s scenario where nothing happens; median of {rounds}):")
    medians = {name: statistics.median(values) for name, values in shares.items() if values}
    for name, share in medians.items():
        print(f"  {name:<26}{100 * share:5.1f} % of one core")
    shipped, ticking_share = (
        medians.get("wake_on (as shipped)"),
        medians.get("every tree at its rate"),
    )
    if shipped is not None and ticking_share:
        print(f"  with wake_on / without: {shipped / ticking_share:.2f}")
    if against is not None and shipped is not None:
        earlier = medians.get(f"{against.name} (--against)")
        if earlier:
            print(f"  now / {against.name}: {shipped / earlier:.2f} (target <= 0.50)")


def median_run(runs: list[Run]) -> Run:
    return Run(
        statistics.median(r.wall_s for r in runs),
        statistics.median(r.user_s for r in runs),
        statistics.median(r.system_s for r in runs),
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--seconds", type=float, default=15.0, help="how long vest run runs (default 15)"
    )
    parser.add_argument(
        "--repeat", type=int, default=4, help="runs of each baseline, half before and half after"
    )
    parser.add_argument(
        "--skip",
        type=float,
        default=1.0,
        help="seconds after the scenario began left out of the /proc reading (default 1)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    parser.add_argument(
        "--against",
        type=Path,
        metavar="FOLDER",
        help="a checkout of an earlier commit: its idle robot is measured too",
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.seconds, args.repeat, args.skip = 3.0, 2, 0.5
    if args.seconds <= 1.0 or args.repeat < 2 or not 0 <= args.skip < args.seconds:
        parser.error("--seconds above 1, --repeat at least 2, --skip within 0..--seconds")

    run_args = ["run", "--duration"]
    baselines: dict[str, list[str]] = {
        'python -c "import engine.cli"': IMPORT_ONLY,
        "vest run --duration 0.01": [*VEST, *run_args, "0.01"],
    }
    measured: dict[str, list[Run]] = {name: [] for name in baselines}
    for command in baselines.values():  # warm the file cache first, untimed
        measure(command)
    for _ in range(args.repeat // 2):
        for name, command in baselines.items():
            measured[name].append(measure(command))
    long_run = measure([*VEST, *run_args, f"{args.seconds:g}"], sample=True)
    for _ in range(args.repeat - args.repeat // 2):
        for name, command in baselines.items():
            measured[name].append(measure(command))

    medians = {name: median_run(runs) for name, runs in measured.items()}
    imports = medians['python -c "import engine.cli"']
    short = medians["vest run --duration 0.01"]
    actions = [m.group(1) for m in map(TIMELINE_LINE.match, long_run.output.splitlines()) if m]
    acted = sum(1 for who in actions if who != "world")
    print(
        f"CPU use of `vest run --duration {args.seconds:g}` (real time, simulated vest, every "
        f"tree and poller; the demo scenario: {len(actions) - acted} world events, {acted} robot "
        f"actions); Python "
        f"{platform.python_version()}, {os.cpu_count()} CPUs"
    )
    print(f"  {'run':<48}{'wall s':>8}{'CPU s':>8}{'user s':>8}{'sys s':>8}")
    rows = [(f"{name} (median of {len(measured[name])})", medians[name]) for name in baselines] + [
        (f"vest run --duration {args.seconds:g}", long_run)
    ]
    for name, run in rows:
        print(
            f"  {name:<48}{run.wall_s:>8.2f}{run.cpu_s:>8.2f}{run.user_s:>8.2f}{run.system_s:>8.2f}"
        )
    total = long_run.cpu_s / long_run.wall_s
    steady = (long_run.cpu_s - short.cpu_s) / (long_run.wall_s - short.wall_s)
    print(f"  total:        {100 * total:5.1f} % of one core (CPU / wall of the long run)")
    print(
        f"  steady state: {100 * steady:5.1f} % of one core (long run minus the short run: "
        f"{long_run.cpu_s - short.cpu_s:.2f} s CPU in {long_run.wall_s - short.wall_s:.2f} s)"
    )
    inside = steady_window(long_run, args.skip)
    if inside is not None:
        share, t0, t1 = inside
        print(
            f"  steady state: {100 * share:5.1f} % of one core, read inside the run "
            f"(/proc/PID/stat, {t0:.1f} s .. {t1:.1f} s after the start, the scenario running)"
        )
    print(
        f"  start-up: {imports.cpu_s:.2f} s CPU for Python and the imports, "
        f"{short.cpu_s - imports.cpu_s:+.2f} s more for vest run's own start-up and shutdown"
    )
    if args.against is not None and not (args.against / "engine" / "cli").is_dir():
        parser.error(f"--against {args.against}: not a checkout of vest (no engine/cli)")
    idle_robot(args.seconds, args.skip, 1 if args.quick else 3, args.against)
    return 0


if __name__ == "__main__":
    sys.exit(main())
