"""What the bus manager adds to one I2C transaction, against calling the bus directly.

Run: ``python bench/bench_bus_overhead.py`` (``--help`` for options).

One simulated I2C bus with a trivial chip; the same ``read_byte_data`` is timed, one
transaction at a time, three ways in one run, in interleaved rounds so that drift in the
machine's speed hits all three alike:

- direct: ``bus.read_byte_data(address, register)``;
- threaded submit: ``handle.submit(read).result()`` through a :class:`BusManager` with its
  worker thread (how the robot runs; this is the figure held against the target);
- threaded call: ``handle.call(read)`` on the same manager, which runs the transaction in
  the calling thread when the bus is idle;
- inline: ``handle.submit(read).result()`` through ``BusManager(threaded=False)`` (how
  virtual-clock runs go).

For scale it also times a bare hand-off, no manager at all: a thread that takes a job from
a ``queue.SimpleQueue`` and answers on a ``Future``, sleeping in between. That is what any
worker-thread design pays to wake its worker and be woken back.

Back to back, the manager's worker often finds the next transaction queued before it goes
back to sleep and skips a wake-up, so it can beat the bare hand-off. A poller at a fixed
rate finds the worker asleep every time; the last rows time that (a short gap on the real
clock before each transaction) and say what such an isolated transaction costs.

Target (DESIGN.md, performance): the threaded manager adds at most 50 us per transaction
at the median.
"""

from __future__ import annotations

import argparse
import os
import platform
import queue
import statistics
import sys
import threading
from collections.abc import Callable
from concurrent.futures import Future
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

from engine.clock import RealClock, stopwatch
from engine.drivers.bus_manager import BusManager
from engine.drivers.device_stats import percentile
from engine.sim.i2c_bus import RegisterFile, SimI2CBus, SimI2CDevice

TARGET_MEDIAN_ADDED_US = 50.0
GAP_S = 0.0005  # pause before each isolated transaction, real seconds
CHIP_ADDRESS = 0x18
REGISTER = 0x05


class TrivialChip(SimI2CDevice):
    """Registers with an auto-incrementing pointer, and nothing else to simulate."""

    def __init__(self, address: int) -> None:
        super().__init__(address)
        self.registers = RegisterFile()
        self.registers.bytes[REGISTER] = 0x42

    def write(self, data: bytes) -> None:
        if data:
            self.registers.pointer = data[0]
            for value in data[1:]:
                self.registers.bytes[self.registers.pointer] = value
                self.registers.advance()

    def read(self, length: int) -> bytes:
        out = bytearray()
        for _ in range(length):
            out.append(self.registers.bytes[self.registers.pointer])
            self.registers.advance()
        return bytes(out)


class BareHandoff:
    """A worker thread and a queue, nothing else: the floor of any thread hand-off."""

    def __init__(self, bus: SimI2CBus) -> None:
        self._bus = bus
        self._jobs: queue.SimpleQueue[tuple[Future[int], Callable[[SimI2CBus], int]] | None]
        self._jobs = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._work, name="bare-handoff", daemon=True)
        self._thread.start()

    def _work(self) -> None:
        while (job := self._jobs.get()) is not None:
            future, fn = job
            if future.set_running_or_notify_cancel():
                future.set_result(fn(self._bus))

    def submit(self, fn: Callable[[SimI2CBus], int]) -> Future[int]:
        future: Future[int] = Future()
        self._jobs.put((future, fn))
        return future

    def close(self) -> None:
        self._jobs.put(None)
        self._thread.join()


def time_each(
    transaction: Callable[[], object],
    count: int,
    into: list[float],
    before: Callable[[], object] | None = None,
) -> None:
    """Run ``transaction`` ``count`` times, appending each one's duration in microseconds.

    ``before`` runs untimed before each transaction (a pause, so that workers fall asleep).
    """
    for _ in range(count):
        if before is not None:
            before()
        started = stopwatch()
        transaction()
        into.append((stopwatch() - started) * 1e6)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--transactions", type=int, default=20_000, help="per way of calling (default 20000)"
    )
    parser.add_argument("--rounds", type=int, default=20, help="interleaved rounds (default 20)")
    parser.add_argument(
        "--strict", action="store_true", help="exit 1 when the median overhead misses the target"
    )
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.transactions, args.rounds = 400, 2
    if args.transactions < args.rounds or args.rounds < 1:
        parser.error("--transactions must be at least --rounds, and --rounds at least 1")

    clock = RealClock()
    bus = SimI2CBus(clock)
    bus.attach(TrivialChip(CHIP_ADDRESS))
    threaded: BusManager[SimI2CBus] = BusManager(bus, name="1", clock=clock)
    inline: BusManager[SimI2CBus] = BusManager(bus, name="1", clock=clock, threaded=False)
    threaded_handle = threaded.claim("chip", CHIP_ADDRESS)
    inline_handle = inline.claim("chip", CHIP_ADDRESS)
    bare = BareHandoff(bus)

    def read(smbus: SimI2CBus) -> int:
        return smbus.read_byte_data(CHIP_ADDRESS, REGISTER)

    ways: dict[str, Callable[[], object]] = {
        "direct": lambda: bus.read_byte_data(CHIP_ADDRESS, REGISTER),
        "bare hand-off": lambda: bare.submit(read).result(),
        "threaded submit": lambda: threaded_handle.submit(read).result(),
        "threaded call": lambda: threaded_handle.call(read),
        "inline": lambda: inline_handle.submit(read).result(),
    }
    samples: dict[str, list[float]] = {way: [] for way in ways}
    round_medians: dict[str, list[float]] = {way: [] for way in ways}
    for transaction in ways.values():  # warm up caches and the worker
        time_each(transaction, 500, [])
    per_round = args.transactions // args.rounds
    names = list(ways)
    started = stopwatch()
    for index in range(args.rounds):
        # rotate the order each round, so no way always runs right after the same other
        shift = index % len(names)
        for way in names[shift:] + names[:shift]:
            this_round: list[float] = []
            time_each(ways[way], per_round, this_round)
            samples[way].extend(this_round)
            round_medians[way].append(statistics.median(this_round))
    # isolated transactions: the worker has gone back to sleep before each one
    isolated = max(200, per_round * args.rounds // 20)
    isolated_ways = {"direct": ways["direct"], "threaded submit": ways["threaded submit"]}
    isolated_samples: dict[str, list[float]] = {way: [] for way in isolated_ways}
    for way, transaction in isolated_ways.items():
        time_each(transaction, isolated, isolated_samples[way], lambda: clock.sleep(GAP_S))
    elapsed_s = stopwatch() - started
    threaded.close()
    inline.close()
    bare.close()

    medians = {way: statistics.median(values) for way, values in samples.items()}
    direct_us = medians["direct"]
    print(
        f"bus manager overhead: {per_round * args.rounds} read_byte_data per way, "
        f"{args.rounds} interleaved rounds, {elapsed_s:.1f} s; Python {platform.python_version()}, "
        f"{os.cpu_count()} CPUs"
    )
    print(
        f"  {'way':<18}{'median us':>10}{'p99 us':>10}{'added (median) us':>19}"
        f"{'round medians us':>20}"
    )
    for way, values in samples.items():
        ordered = sorted(values)
        added_text = "-" if way == "direct" else f"{medians[way] - direct_us:+.1f}"
        spread = f"{min(round_medians[way]):.1f}..{max(round_medians[way]):.1f}"
        print(
            f"  {way:<18}{medians[way]:>10.1f}{percentile(ordered, 0.99):>10.1f}"
            f"{added_text:>19}{spread:>20}"
        )
    added_us = medians["threaded submit"] - direct_us
    verdict = "OK" if added_us <= TARGET_MEDIAN_ADDED_US else "OVER TARGET"
    print(
        f"bus manager overhead: median {added_us:+.1f} us per transaction "
        f"(target <= {TARGET_MEDIAN_ADDED_US:g} us): {verdict}"
    )
    isolated_medians = {w: statistics.median(v) for w, v in isolated_samples.items()}
    isolated_added_us = isolated_medians["threaded submit"] - isolated_medians["direct"]
    isolated_p99_us = percentile(sorted(isolated_samples["threaded submit"]), 0.99)
    print(
        f"  isolated ({isolated} transactions, {GAP_S * 1e6:.0f} us apart, the worker asleep "
        f"before each): threaded submit median {isolated_medians['threaded submit']:.1f} us, "
        f"p99 {isolated_p99_us:.1f} us, added {isolated_added_us:+.1f} us"
    )
    print(
        f"  the thread hand-off alone (bare queue + future, no manager) adds "
        f"{medians['bare hand-off'] - direct_us:+.1f} us; the manager's own work (inline "
        f"mode, same code without the hand-off) {medians['inline'] - direct_us:+.1f} us; "
        f"call() on an idle bus {medians['threaded call'] - direct_us:+.1f} us"
    )
    return 1 if args.strict and verdict != "OK" else 0


if __name__ == "__main__":
    sys.exit(main())
