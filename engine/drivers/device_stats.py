"""What each device's transactions did: the counters a bus manager keeps, and their snapshot.

:class:`DeviceRecord` is one claimed device's running state (online or not, counters,
recent latencies), mutated by its :class:`~engine.drivers.bus_manager.BusManager` under
the manager's lock; :class:`DeviceStats` is the plain, frozen snapshot the debug tools,
``vest devices`` and the live view read.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["DeviceRecord", "DeviceStats", "percentile"]


def percentile(sorted_values: Sequence[float], fraction: float) -> float:
    """The nearest-rank percentile of ``sorted_values`` (ascending); ``0.0`` when empty.

    ``fraction`` is in 0..1 (``0.99`` for p99).
    """
    if not 0.0 <= fraction <= 1.0:
        raise ValueError(f"percentile fraction must be within 0..1, got {fraction}")
    if not sorted_values:
        return 0.0
    rank = max(1, math.ceil(fraction * len(sorted_values)))
    return float(sorted_values[rank - 1])


@dataclass(frozen=True, slots=True)
class DeviceStats:
    """What one device's transactions did, as a plain snapshot for the debug tools.

    Latencies are the time a transaction held the bus, retries and backoff included,
    over the most recent transactions (the manager's ``latency_window``), in microseconds.
    """

    device: str
    bus: str
    address: int | None
    online: bool
    transactions: int
    """Transactions that reached the bus (probes and refused polls not counted)."""
    errors: int
    """Transactions that failed, after their retries (implausible readings included)."""
    retries: int
    """Extra attempts made after a retryable bus error."""
    refused: int
    """Polls answered "offline" without touching the bus."""
    probes: int
    """Re-probes made while the device was offline."""
    consecutive_failures: int
    latency_p50_us: float
    latency_p99_us: float
    latency_max_us: float
    last_error: str | None
    implausible: int = 0
    """Readings the driver refused as outside what its chip can report
    (:class:`~engine.drivers.device_errors.ImplausibleReadingError`)."""


class DeviceRecord:
    """A claim and its running state; guarded by its bus manager's lock."""

    __slots__ = (
        "address",
        "consecutive_failures",
        "errors",
        "implausible",
        "last_error",
        "latencies_us",
        "latency_max_us",
        "name",
        "next_probe_s",
        "online",
        "probe",
        "probes",
        "refused",
        "retries",
        "transactions",
    )

    def __init__(
        self,
        name: str,
        address: int | None,
        probe: Callable[[Any], object] | None,
        latency_window: int,
    ) -> None:
        self.name = name
        self.address = address
        self.probe = probe
        self.online = True
        self.consecutive_failures = 0
        self.next_probe_s = 0.0
        """Clock seconds when an offline device is next re-probed."""
        self.transactions = 0
        self.errors = 0
        self.retries = 0
        self.refused = 0
        self.probes = 0
        self.implausible = 0
        self.latencies_us: deque[float] = deque(maxlen=latency_window)
        self.latency_max_us = 0.0
        self.last_error: str | None = None

    def add_latency(self, latency_us: float) -> None:
        """Count one transaction that reached the bus and held it ``latency_us`` us."""
        self.transactions += 1
        self.latencies_us.append(latency_us)
        self.latency_max_us = max(self.latency_max_us, latency_us)

    def frozen(self) -> tuple[Any, ...]:
        """The counters as they are now (lock held); :func:`snapshot` makes them stats."""
        return (
            self.name,
            self.address,
            self.online,
            self.transactions,
            self.errors,
            self.retries,
            self.refused,
            self.probes,
            self.consecutive_failures,
            sorted(self.latencies_us),
            self.latency_max_us,
            self.last_error,
            self.implausible,
        )


def snapshot(bus: str, frozen: tuple[Any, ...]) -> DeviceStats:
    """Stats from :meth:`DeviceRecord.frozen` (outside the lock: sorting is done, percentiles
    are cheap)."""
    (name, address, online, txn, err, ret, ref, prb, cons, lat, lat_max, last, impl) = frozen
    return DeviceStats(
        device=name,
        bus=bus,
        address=address,
        online=online,
        transactions=txn,
        errors=err,
        retries=ret,
        refused=ref,
        probes=prb,
        consecutive_failures=cons,
        latency_p50_us=percentile(lat, 0.50),
        latency_p99_us=percentile(lat, 0.99),
        latency_max_us=lat_max,
        last_error=last,
        implausible=impl,
    )
