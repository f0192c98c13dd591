"""Volts-to-newtons calibration of a force pad (an FSR in a voltage divider).

An FSR's curve depends on the part, its mounting and the divider resistor, so the driver
hard-codes none: the robot config holds a measured table per pad, for example::

    force_left:
      calibration: [[0.0, 0.0], [0.82, 0.2], [2.06, 1.0], [3.11, 10.0]]   # volts, newtons

and :class:`ForceCalibration` interpolates it piecewise-linearly, clamped at both ends.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

from engine.errors import ConfigError


class ForceCalibration:
    """A piecewise-linear map from divider volts to newtons.

    ``points`` are ``(volts, newtons)`` pairs: at least two, volts strictly increasing,
    newtons never decreasing (a harder squeeze never reads as a lighter one), all finite
    and newtons not negative. A bad table raises :class:`ConfigError` (a ``ValueError``).
    """

    def __init__(self, points: Sequence[tuple[float, float]]) -> None:
        table = [self._point(index, point) for index, point in enumerate(points)]
        if len(table) < 2:
            raise ConfigError(
                f"force calibration needs at least two (volts, newtons) points, got {len(table)}"
            )
        for index in range(1, len(table)):
            (v0, n0), (v1, n1) = table[index - 1], table[index]
            if v1 <= v0:
                raise ConfigError(
                    f"force calibration point {index} ({v1} V) must have more volts than "
                    f"point {index - 1} ({v0} V): volts must be strictly increasing"
                )
            if n1 < n0:
                raise ConfigError(
                    f"force calibration point {index} ({n1} N) has less force than point "
                    f"{index - 1} ({n0} N): newtons must not decrease"
                )
        self._volts = [v for v, _ in table]
        self._newtons = [n for _, n in table]

    @staticmethod
    def _point(index: int, point: tuple[float, float]) -> tuple[float, float]:
        try:
            volts, newtons = (float(value) for value in point)
        except (TypeError, ValueError) as error:
            raise ConfigError(
                f"force calibration point {index} {point!r} is not a (volts, newtons) pair"
            ) from error
        if not (math.isfinite(volts) and math.isfinite(newtons)):
            raise ConfigError(f"force calibration point {index} {point!r} is not finite")
        if newtons < 0:
            raise ConfigError(f"force calibration point {index} has negative force {newtons} N")
        return volts, newtons

    @property
    def points(self) -> list[tuple[float, float]]:
        """The table as ``(volts, newtons)`` pairs."""
        return list(zip(self._volts, self._newtons, strict=True))

    def newtons(self, volts: float) -> float:
        """The force in newtons for a divider reading in volts (clamped to the table)."""
        if math.isnan(volts):
            raise ValueError("force calibration cannot convert NaN volts")
        if volts <= self._volts[0]:
            return self._newtons[0]
        if volts >= self._volts[-1]:
            return self._newtons[-1]
        right = bisect.bisect_right(self._volts, volts)
        v0, v1 = self._volts[right - 1], self._volts[right]
        n0, n1 = self._newtons[right - 1], self._newtons[right]
        return n0 + (n1 - n0) * (volts - v0) / (v1 - v0)

    def __repr__(self) -> str:
        return f"ForceCalibration({self.points!r})"
