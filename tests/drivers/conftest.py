"""Shared fixtures of the driver tests: a virtual clock and a simulated I2C bus on it."""

import pytest

from engine.clock import VirtualClock
from engine.drivers.sim.i2c_bus import SimI2CBus


@pytest.fixture
def clock() -> VirtualClock:
    """Time that moves only when a test advances it."""
    return VirtualClock()


@pytest.fixture
def bus(clock: VirtualClock) -> SimI2CBus:
    """An empty simulated I2C bus: a test solders on the chips it needs."""
    return SimI2CBus(clock)
