"""What the bus manager adds to one I2C transaction, against calling the bus directly.

Run: ``python bench/bench_bus_overhead.py`` (``--help`` for options).

One simulated I2C bus with a trivial chip; the same ``read_byte_data`` is timed, one
transaction at a time, three ways in one run, in interleaved rounds so that drift in the
machine's speed hits all three alike:

- direct: ``bus.read_byte_data(address, register)``;
- threaded: ``handle.submit(read).result()`` through a :class:`BusManager` with its worker
  thread (how the robot runs);
- inline: the same through ``BusManager(threaded=False)`` (how virtual-clock runs go).

Target (DESIGN.md, performance): the threaded manager adds at most 50 us per transaction
at the median.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout

from engine.clock import RealClock, stopwatch  # noqa: E402
from engine.drivers.bus_manager import BusManager, percentile  # noqa: E402
from engine.drivers.sim.i2c_bus import RegisterFile, SimI2CBus, SimI2CDevice  # noqa: E402

TARGET_MEDIAN_ADDED_US = 50.0
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


def time_each(transaction: Callable[[], object], count: int, into: list[float]) -> None:
    """Run ``transaction`` ``count`` times, appending each one's duration in microseconds."""
    for _ in range(count):
        started = stopwatch()
        transaction()
        into.append((stopwatch() - started) * 1e6)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--transactions", type=int, default=20_000, help="per way of calling (default 20000)"
    )
    parser.add_argument("--rounds", type=int, default=10, help="interleaved rounds (default 10)")
    parser.add_argument(
        "--strict", action="store_true", help="exit 1 when the median overhead misses the target"
    )
    args = parser.parse_args(argv)
    if args.transactions < args.rounds or args.rounds < 1:
        parser.error("--transactions must be at least --rounds, and --rounds at least 1")

    clock = RealClock()
    bus = SimI2CBus(clock)
    bus.attach(TrivialChip(CHIP_ADDRESS))
    threaded: BusManager[SimI2CBus] = BusManager(bus, name="1", clock=clock)
    inline: BusManager[SimI2CBus] = BusManager(bus, name="1", clock=clock, threaded=False)
    threaded_handle = threaded.claim("chip", CHIP_ADDRESS)
    inline_handle = inline.claim("chip", CHIP_ADDRESS)

    def read(smbus: SimI2CBus) -> int:
        return smbus.read_byte_data(CHIP_ADDRESS, REGISTER)

    ways: dict[str, Callable[[], object]] = {
        "direct": lambda: bus.read_byte_data(CHIP_ADDRESS, REGISTER),
        "threaded": lambda: threaded_handle.submit(read).result(),
        "inline": lambda: inline_handle.submit(read).result(),
    }
    samples: dict[str, list[float]] = {way: [] for way in ways}
    for way, transaction in ways.items():  # warm up caches and the worker
        time_each(transaction, 500, [])
    per_round = args.transactions // args.rounds
    started = stopwatch()
    for _ in range(args.rounds):
        for way, transaction in ways.items():
            time_each(transaction, per_round, samples[way])
    elapsed_s = stopwatch() - started
    threaded.close()
    inline.close()

    medians = {way: statistics.median(values) for way, values in samples.items()}
    print(
        f"bus manager overhead: {per_round * args.rounds} read_byte_data per way, "
        f"{args.rounds} interleaved rounds, {elapsed_s:.1f} s; Python {platform.python_version()}, "
        f"{os.cpu_count()} CPUs"
    )
    print(f"  {'way':<10}{'median us':>12}{'p99 us':>12}{'added (median) us':>20}")
    for way, values in samples.items():
        ordered = sorted(values)
        added = medians[way] - medians["direct"]
        added_text = "-" if way == "direct" else f"{added:+.1f}"
        print(
            f"  {way:<10}{medians[way]:>12.1f}{percentile(ordered, 0.99):>12.1f}{added_text:>20}"
        )
    added_us = medians["threaded"] - medians["direct"]
    verdict = "OK" if added_us <= TARGET_MEDIAN_ADDED_US else "OVER TARGET"
    print(
        f"bus manager overhead: median {added_us:+.1f} us per transaction "
        f"(target <= {TARGET_MEDIAN_ADDED_US:g} us): {verdict}"
    )
    print(
        f"  (inline mode, no thread hand-off: median "
        f"{medians['inline'] - medians['direct']:+.1f} us)"
    )
    return 1 if args.strict and verdict != "OK" else 0


if __name__ == "__main__":
    sys.exit(main())
