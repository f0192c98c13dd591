"""How long `vest validate` takes on a 10,000-node tree, against reading the same file.

Run: ``.venv/bin/python bench/bench_validate.py`` (``--nodes N``, ``--rounds R``).

A tree of N/2 Check + Say pairs under one Sequence is written to a temporary folder and
validated in-process (``engine.cli.main(["validate", FILE])``, as a therapist runs it),
in interleaved rounds with three baselines measured in the same run on the same file:

- careful: the same validate with libyaml switched off, i.e. PyYAML's pure-Python reader
  (how every file was read before the fast reader);
- yaml C: ``yaml.load(text, Loader=yaml.CSafeLoader)``, plain values without places, the
  least any YAML reading of this file can cost;
- yaml py: ``yaml.safe_load(text)``, the same in pure Python.

Target (issue 7): 10k nodes validate in under 2 s. The ratio to "yaml C" says what the
places, the checks and the building cost on top of parsing.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import platform
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import yaml

import engine.files.yaml_events as yaml_events
from engine.cli import main


def write_tree(folder: Path, nodes: int) -> Path:
    lines = ["name: big", "rate_hz: 10", "root:", "  Sequence:"]
    for i in range(nodes // 2):
        lines.append("    - Check: {key: /sensors/touch/any, equals: true}")
        lines.append(f'    - Say: {{text: "hello {i}"}}')
    path = folder / "big.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def validate(path: Path) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["validate", str(path)]) == 0


def validate_carefully(path: Path) -> None:
    parser = yaml_events.PARSER
    yaml_events.PARSER = None
    try:
        validate(path)
    finally:
        yaml_events.PARSER = parser


def timed(work: Callable[[], None]) -> float:
    start = time.perf_counter()
    work()
    return time.perf_counter() - start


def run(nodes: int, rounds: int) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = write_tree(Path(folder), nodes)
        text = path.read_text()
        ways: dict[str, Callable[[], None]] = {
            "vest validate": lambda: validate(path),
            "careful (pure-Python YAML)": lambda: validate_carefully(path),
            "yaml C (no places)": lambda: yaml.load(text, Loader=yaml.CSafeLoader),
            "yaml py (no places)": lambda: yaml.safe_load(text),
        }
        validate(path)  # imports and first-use costs out of the way
        times: dict[str, list[float]] = {name: [] for name in ways}
        for round_number in range(rounds):
            names = list(ways)
            names = names[round_number % len(names) :] + names[: round_number % len(names)]
            for name in names:
                times[name].append(timed(ways[name]))
    print(
        f"vest validate on a {nodes}-node tree ({len(text) / 1024:.0f} KiB), {rounds} "
        f"interleaved rounds; Python {platform.python_version()}, libyaml "
        f"{'yes' if yaml.__with_libyaml__ else 'no'}"
    )
    base = statistics.median(times["yaml C (no places)"])
    print(f"  {'way':28} {'median s':>9} {'min s':>8} {'x yaml C':>9}")
    for name, samples in times.items():
        median = statistics.median(samples)
        print(f"  {name:28} {median:9.3f} {min(samples):8.3f} {median / base:8.1f}x")
    median = statistics.median(times["vest validate"])
    verdict = "OK" if median < 2.0 else "OVER"
    careful = statistics.median(times["careful (pure-Python YAML)"])
    print(f"vest validate: {median:.2f} s (target < 2 s): {verdict}")
    print(f"  {careful / median:.1f}x faster than the careful reader")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=10_000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument(
        "--quick", action="store_true", help="a short run that only shows it still works"
    )
    options = parser.parse_args()
    if options.quick:
        options.nodes, options.rounds = 500, 1
    run(options.nodes, options.rounds)
