"""Every benchmark still runs: each one's --quick run (seconds, not its figures) ends
without an error, so a benchmark that no longer runs fails here, not for a later reader.

Their figures are measured by running them in full (bench/README.md); here only that they
run is checked: no timing is asserted (these machines are noisy)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.bench

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = sorted(path.name for path in (ROOT / "bench").glob("bench_*.py"))


@pytest.mark.parametrize("benchmark", BENCHMARKS)
def test_the_benchmark_still_runs(benchmark: str) -> None:
    ran = subprocess.run(
        [sys.executable, f"bench/{benchmark}", "--quick"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert ran.returncode == 0, ran.stdout[-2000:] + ran.stderr[-3000:]
    assert "Traceback" not in ran.stderr
    assert ran.stdout.strip(), "it printed no figures"


def test_every_benchmark_is_run_here() -> None:
    assert len(BENCHMARKS) >= 10
