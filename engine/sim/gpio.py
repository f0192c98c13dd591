"""A simulated digital output line: the wire from a GPIO pin to a simulated chip's input."""

from __future__ import annotations

from collections.abc import Callable


class SimOutputLine:
    """An :class:`engine.drivers.gpio.OutputLine` whose far end is a Python callback.

    Wire it to the input it drives, e.g. ``SimOutputLine(tof.set_xshut)``. Like a real
    line request, it drives ``initial_high`` as soon as it exists.
    """

    def __init__(self, callback: Callable[[bool], None], *, initial_high: bool = False) -> None:
        self._callback = callback
        self.high = initial_high
        self.changes = 0
        callback(initial_high)

    def set(self, high: bool) -> None:
        """Drive the line; the callback sees every write, as the wire does."""
        self.high = bool(high)
        self.changes += 1
        self._callback(self.high)
