"""The sensors the safety envelope reads, and whether each reading can be trusted.

A distance rule reads the chest's range sensors, a force rule the side force pads. A
reading is trusted only when its device says it is working (``/devices/<name>/ok`` is
true), the reading is fresh (written within :data:`STALE_AFTER_POLLS` of its device's
poll periods) and plausible (a number within what the sensor can measure; a range sensor
may also see nothing at all). A reading that cannot be trusted counts as the worst case:
someone touching the chest, a hard press.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from engine.blackboard.board import Blackboard
from engine.hardware.config import RobotConfig

STALE_AFTER_POLLS = 4
"""A reading older than this many of its device's poll periods is stale."""
DEFAULT_POLL_HZ = 10.0
RANGE_PLAUSIBLE_MM = (0.0, 8190.0)
"""What a time-of-flight range reads (the VL53L0X's field holds up to 8190 mm)."""
FORCE_PLAUSIBLE_N = (-1.0, 200.0)
"""What a side force pad reads (an FSR 406 is made for up to about 100 N; a little below
zero is calibration noise)."""


@dataclass(frozen=True)
class Guard:
    """One sensor a rule reads: its device, its key, how old a reading may be (s), what
    it can plausibly read (``unit``), and whether "nothing" (None) is a reading."""

    device: str
    key: str
    stale_after_s: float
    plausible: tuple[float, float]
    unit: str
    nothing_is_a_reading: bool


@dataclass(frozen=True)
class GuardReading:
    """A guard's reading now: ``value`` (None: nothing sensed) and, when it cannot be
    trusted, ``doubt`` saying why (then ``value`` is meaningless)."""

    guard: Guard
    value: float | None
    doubt: str | None = None


def _stale_after(rate_hz: float | None) -> float:
    return STALE_AFTER_POLLS / (rate_hz or DEFAULT_POLL_HZ)


def range_guards(robot: RobotConfig) -> tuple[Guard, ...]:
    """The chest's range sensors, in the config's order."""
    return tuple(
        Guard(
            device.name,
            device.keys["range"],
            _stale_after(device.rate_hz),
            RANGE_PLAUSIBLE_MM,
            "mm",
            nothing_is_a_reading=True,
        )
        for device in robot.with_role("range")
        if "range" in device.keys
    )


def force_guards(robot: RobotConfig) -> tuple[Guard, ...]:
    """The side force pads (one guard per pad), in the config's order."""
    return tuple(
        Guard(
            device.name,
            pad.key,
            _stale_after(device.rate_hz),
            FORCE_PLAUSIBLE_N,
            "N",
            nothing_is_a_reading=False,
        )
        for device in robot.with_role("force")
        for pad in device.pads
    )


def read_guard(guard: Guard, blackboard: Blackboard, now_s: float) -> GuardReading:
    """What ``guard`` reads on the committed blackboard at ``now_s`` (clock seconds)."""
    ok = blackboard.get(f"/devices/{guard.device}/ok")
    if ok is not True:
        doubt = "has not reported yet" if ok is None else "is offline"
        return GuardReading(guard, None, f"{guard.device} {doubt}")
    written_s = blackboard.updated_s(guard.key)
    if written_s is None:
        return GuardReading(guard, None, f"{guard.device} has given no reading yet")
    age_s = now_s - written_s
    if age_s > guard.stale_after_s + 1e-9:
        return GuardReading(
            guard, None, f"{guard.device}'s last reading is {age_s:.2f} s old (stale)"
        )
    value = blackboard.get(guard.key)
    if value is None and guard.nothing_is_a_reading:
        return GuardReading(guard, None)
    low, high = guard.plausible
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or not low <= value <= high
    ):
        return GuardReading(
            guard,
            None,
            f"{guard.device} reads {value!r}, not a plausible {guard.unit} reading "
            f"({low:g}..{high:g})",
        )
    return GuardReading(guard, float(value))
