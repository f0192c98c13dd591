"""Per-tree tick statistics: how long ticks take and how late they start."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

WINDOW = 10_000


def percentile(values: list[float], fraction: float) -> float:
    """The ``fraction`` (0..1) percentile of ``values`` by nearest rank (0 when empty)."""
    if not values:
        return 0.0
    ordered = sorted(values)
    index = min(len(ordered) - 1, max(0, round(fraction * (len(ordered) - 1))))
    return ordered[index]


@dataclass
class TickStats:
    """Counts and the most recent :data:`WINDOW` samples, in seconds."""

    ticks: int = 0
    skipped: int = 0
    errors: int = 0
    durations_s: deque[float] = field(default_factory=lambda: deque(maxlen=WINDOW))
    lateness_s: deque[float] = field(default_factory=lambda: deque(maxlen=WINDOW))

    def record(self, duration_s: float, lateness_s: float) -> None:
        self.ticks += 1
        self.durations_s.append(duration_s)
        self.lateness_s.append(lateness_s)

    def summary(self) -> dict[str, float]:
        """p50/p99/max of tick duration and lateness in milliseconds, and the counts."""
        durations, lateness = list(self.durations_s), list(self.lateness_s)
        return {
            "ticks": self.ticks,
            "skipped": self.skipped,
            "errors": self.errors,
            "duration_p50_ms": percentile(durations, 0.50) * 1e3,
            "duration_p99_ms": percentile(durations, 0.99) * 1e3,
            "duration_max_ms": max(durations, default=0.0) * 1e3,
            "lateness_p50_ms": percentile(lateness, 0.50) * 1e3,
            "lateness_p99_ms": percentile(lateness, 0.99) * 1e3,
            "lateness_max_ms": max(lateness, default=0.0) * 1e3,
        }
