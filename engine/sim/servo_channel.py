"""One servo channel of the simulated Maestro: how its position follows its target.

Every 10 ms update the position steps toward the target by at most the speed limit, the
speed changing by at most the acceleration limit and ramping down before the target, as
the Maestro user's guide describes it (section 4). Kept apart from the emulator's serial
protocol so the motion model can be read, and tested, on its own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal


@dataclass
class ServoChannel:
    """One Maestro servo channel; positions and targets in quarter-microseconds.

    ``speed`` is in (0.25 us)/(10 ms) and ``acceleration`` in (0.25 us)/(10 ms)/(80 ms),
    as the Maestro's own registers; 0 means unlimited for both.
    """

    min_qus: int
    max_qus: int
    home: int | Literal["off", "ignore"]
    target: int = 0
    position: float = 0.0
    velocity: float = 0.0  # quarter-us per tick, signed
    speed: int = 0
    acceleration: int = 0

    def set_target(self, quarter_us: int) -> None:
        if quarter_us == 0:
            self.target, self.position, self.velocity = 0, 0.0, 0.0
            return
        self.target = min(max(quarter_us, self.min_qus), self.max_qus)
        # An off servo's whereabouts are unknown, so it goes straight to a new target.
        if self.position == 0 or (self.speed == 0 and self.acceleration == 0):
            self.position, self.velocity = float(self.target), 0.0

    def go_home(self) -> None:
        if self.home == "off":
            self.set_target(0)
        elif isinstance(self.home, int):  # "ignore" leaves the channel as it is
            self.set_target(self.home)

    @property
    def moving(self) -> bool:
        return round(self.position) != self.target

    def step(self, ticks: int) -> None:
        """Advance ``ticks`` 10 ms updates."""
        if ticks <= 0 or (self.position == self.target and self.velocity == 0.0):
            return
        if self.acceleration == 0:
            self.velocity = 0.0
            distance = self.target - self.position
            if self.speed == 0 or abs(distance) <= self.speed * ticks:
                self.position = float(self.target)
            else:
                self.position += math.copysign(self.speed * ticks, distance)
            return
        accel = self.acceleration / 8  # per 10 ms tick: the unit is per 80 ms
        top_speed = self.speed if self.speed else math.inf
        for _ in range(ticks):
            distance = self.target - self.position
            if distance == 0 and self.velocity == 0.0:
                return
            # Fastest speed from which it can still stop at the target.
            braking = math.sqrt(2 * accel * abs(distance))
            wanted = math.copysign(min(top_speed, braking), distance)
            self.velocity = min(max(wanted, self.velocity - accel), self.velocity + accel)
            self.position += self.velocity
            toward = distance * self.velocity > 0
            if toward and (self.target - self.position) * distance <= 0:
                self.position, self.velocity = float(self.target), 0.0
