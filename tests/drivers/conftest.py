"""Shared fixtures of the driver tests: a virtual clock, a simulated I2C bus on it, and a
way to read a chip that answers garbage."""

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

import pytest

from engine.clock import VirtualClock
from engine.drivers.device_errors import ImplausibleReadingError
from engine.sim.i2c_bus import SimI2CBus

R = TypeVar("R")


@pytest.fixture
def clock() -> VirtualClock:
    """Time that moves only when a test advances it."""
    return VirtualClock()


@pytest.fixture
def bus(clock: VirtualClock) -> SimI2CBus:
    """An empty simulated I2C bus: a test solders on the chips it needs."""
    return SimI2CBus(clock)


@dataclass
class GarbageReadings(Generic[R]):
    """What a driver made of a chip answering random bytes: believed or refused."""

    believed: list[R] = field(default_factory=list)
    refused: list[ImplausibleReadingError] = field(default_factory=list)


def _read_garbage(
    bus: SimI2CBus, address: int, read: Callable[[], R], *, times: int = 200
) -> GarbageReadings[R]:
    """Make the chip at ``address`` answer random bytes, then ``read()`` it ``times`` times.

    The bus's random bytes come from a fixed seed, so every run sees the same garbage.
    """
    bus.inject("garbage", 3600.0, address)
    readings: GarbageReadings[R] = GarbageReadings()
    for _ in range(times):
        try:
            readings.believed.append(read())
        except ImplausibleReadingError as refusal:
            readings.refused.append(refusal)
    return readings


ReadGarbage = Callable[..., GarbageReadings[Any]]


@pytest.fixture
def read_garbage() -> ReadGarbage:
    """``read_garbage(bus, address, read)``: a chip answering random bytes, read many times."""
    return _read_garbage
