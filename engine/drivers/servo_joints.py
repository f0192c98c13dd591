"""The robot's servo joints: names, limits, and moves in degrees on a Maestro.

A :class:`Joint` maps its angle range linearly onto its pulse-width range and carries a
speed limit; :class:`ServoJoints` refuses any move outside those limits (it never clamps)
and turns a speed in degrees per second into the Maestro's speed limit for that joint, so
no command it sends can drive a joint beyond what its config allows.

The joints' pulse limits should match the Min/Max set on the Maestro itself: the Maestro
silently clamps targets to its own limits.
"""

from __future__ import annotations

import errno
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any, Protocol

from engine.clock import Clock
from engine.drivers.maestro_protocol import us_to_quarter_us
from engine.errors import ConfigError, DeviceError, ServiceError

MAESTRO_SPEED_UNIT_US_PER_S = 0.25 / 0.010
"""One Maestro speed unit, (0.25 us)/(10 ms), in us per second (25 us/s)."""
MAX_MAESTRO_SPEED = 0x3FFF
MAESTRO_MIN_US = 64.0
"""The shortest servo pulse a Maestro channel can be set to (its lowest Min setting), us."""
MAESTRO_MAX_US = 4000.0
"""The longest pulse a joint may ask for, us: beyond every hobby servo, and within the
4095.75 us a Set Target command can carry."""


class ServoController(Protocol):
    """What :class:`ServoJoints` needs from a servo controller (a :class:`Maestro`)."""

    channels: int

    def set_target_us(self, channel: int, pulse_us: float) -> None: ...

    def set_speed(self, channel: int, speed: int) -> None: ...

    def get_position_us(self, channel: int) -> float: ...

    def is_moving(self) -> bool: ...


@dataclass(frozen=True)
class Joint:
    """A servo joint: ``name`` on Maestro ``channel``.

    Angles in degrees, ``min_deg`` mapping to ``min_us`` and ``max_deg`` to ``max_us``
    (pulse widths in microseconds); ``max_speed_dps`` in degrees per second; the joint rests
    at ``home_deg``.
    """

    name: str
    channel: int
    min_deg: float
    max_deg: float
    max_speed_dps: float
    min_us: float = 1000.0
    max_us: float = 2000.0
    home_deg: float = 0.0
    rest_speed_dps: float | None = None
    """How fast the joint goes home when a behavior is halted (None: a third of its limit)."""

    @property
    def safe_speed_dps(self) -> float:
        """The speed of a move home after a halt, in deg/s."""
        return self.rest_speed_dps or self.max_speed_dps / 3

    def __post_init__(self) -> None:
        where = f"joint {self.name!r}"
        if not self.name:
            raise ValueError("a joint needs a name")
        if not 0 <= self.channel <= 23:
            raise ValueError(f"{where}: channel {self.channel} is outside 0..23")
        if not self.min_deg < self.max_deg:
            raise ValueError(f"{where}: min_deg {self.min_deg} is not below max_deg {self.max_deg}")
        if not 0 < self.min_us < self.max_us:
            raise ValueError(
                f"{where}: pulse limits {self.min_us}..{self.max_us} us are not increasing "
                "and positive"
            )
        if not self.max_speed_dps > 0:
            raise ValueError(f"{where}: max_speed_dps {self.max_speed_dps} must be positive")
        if not self.min_deg <= self.home_deg <= self.max_deg:
            raise ValueError(
                f"{where}: home_deg {self.home_deg} is outside {self.min_deg}..{self.max_deg} deg"
            )
        # The joint's own speed limit must be expressible, or move() could not honour it.
        speed_dps_to_maestro(self, self.max_speed_dps)

    @property
    def us_per_deg(self) -> float:
        """Pulse width change per degree, in us/deg."""
        return (self.max_us - self.min_us) / (self.max_deg - self.min_deg)


def angle_to_us(joint: Joint, angle_deg: float) -> float:
    """The pulse width in us for ``angle_deg``, linear between the joint's pulse limits.

    Does not check the joint's angle limits (``ServoJoints.move`` does).
    """
    span_us, span_deg = joint.max_us - joint.min_us, joint.max_deg - joint.min_deg
    return joint.min_us + (angle_deg - joint.min_deg) * span_us / span_deg


def us_to_angle(joint: Joint, pulse_us: float) -> float:
    """The angle in degrees that a pulse width of ``pulse_us`` us means for ``joint``."""
    span_us, span_deg = joint.max_us - joint.min_us, joint.max_deg - joint.min_deg
    return joint.min_deg + (pulse_us - joint.min_us) * span_deg / span_us


def speed_dps_to_maestro(joint: Joint, speed_dps: float) -> int:
    """``speed_dps`` (deg/s) as a Maestro speed limit, (0.25 us)/(10 ms), for ``joint``.

    Rounded down, so the servo never moves faster than asked; a speed too slow to express
    (below one unit) is refused rather than sent as 0, which would mean unlimited.
    """
    units = math.floor(speed_dps * joint.us_per_deg / MAESTRO_SPEED_UNIT_US_PER_S + 1e-9)
    if units < 1:
        slowest_dps = MAESTRO_SPEED_UNIT_US_PER_S / joint.us_per_deg
        raise ValueError(
            f"joint {joint.name!r}: speed {speed_dps} deg/s is below the slowest the Maestro "
            f"can do for it ({slowest_dps:.3g} deg/s)"
        )
    if units > MAX_MAESTRO_SPEED:
        raise ValueError(
            f"joint {joint.name!r}: speed {speed_dps} deg/s is beyond the Maestro's speed "
            f"limit ({MAX_MAESTRO_SPEED} units)"
        )
    return units


def joints_from_config(section: Mapping[str, Any], *, where: str = "servos") -> list[Joint]:
    """Joints from a config section mapping each joint name to its settings.

    ``{"neck_pan": {"channel": 0, "min_deg": -60, "max_deg": 60, "max_speed_dps": 90,
    "min_us": 1000, "max_us": 2000, "home_deg": 0}}``. Raises ConfigError naming the place
    (``where``), the joint and the setting.
    """
    known = [field.name for field in fields(Joint) if field.name != "name"]
    joints = []
    for name, settings in section.items():
        place = f"{where}.{name}"
        if not isinstance(settings, Mapping):
            raise ConfigError(f"{place}: expected a mapping of settings, got {settings!r}")
        unknown = sorted(set(settings) - set(known))
        if unknown:
            raise ConfigError(f"{place}: unknown setting(s) {unknown}; known: {known}")
        try:
            joints.append(Joint(name=str(name), **settings))
        except TypeError as error:  # a required setting is missing
            raise ConfigError(f"{place}: {error}") from error
        except ValueError as error:
            raise ConfigError(f"{place}: {error}") from error
    return joints


class ServoJoints:
    """Named joints on one servo controller, moved in degrees within their limits.

    ``clock`` paces :meth:`wait_until_still`. Note that a Maestro channel that is off (as
    after power-up with the default "off" home) jumps to its first target at the servo's
    full speed: the Maestro cannot know where an unpowered servo is.
    """

    def __init__(self, maestro: ServoController, joints: Sequence[Joint], *, clock: Clock) -> None:
        self._maestro = maestro
        self._clock = clock
        self._joints: dict[str, Joint] = {}
        channels: dict[int, str] = {}
        for joint in joints:
            if joint.name in self._joints:
                raise ValueError(f"joint {joint.name!r} is listed twice")
            if joint.channel in channels:
                raise ValueError(
                    f"joint {joint.name!r}: channel {joint.channel} is already used by "
                    f"{channels[joint.channel]!r}"
                )
            if joint.channel >= maestro.channels:
                raise ValueError(
                    f"joint {joint.name!r}: channel {joint.channel} is outside the "
                    f"controller's 0..{maestro.channels - 1}"
                )
            self._joints[joint.name] = joint
            channels[joint.channel] = joint.name

    @property
    def names(self) -> list[str]:
        """The joints' names, in config order."""
        return list(self._joints)

    def joint(self, name: str) -> Joint:
        """The joint called ``name``; ValueError listing the known names otherwise."""
        try:
            return self._joints[name]
        except KeyError:
            raise ValueError(
                f"unknown joint {name!r}; known joints: {', '.join(self._joints) or 'none'}"
            ) from None

    def move(self, joint_name: str, angle_deg: float, speed_dps: float | None = None) -> None:
        """Start moving ``joint_name`` to ``angle_deg`` degrees at ``speed_dps`` deg/s.

        ``speed_dps`` defaults to the joint's limit. Raises ValueError (naming the joint, the
        value and the limit) for an angle outside the joint's range or a speed above its
        limit, and for a pulse too short to tell from "off" (0); nothing is sent then.
        Raises DeviceError when the controller does not answer the query that confirms the
        move (within its port's read timeout). Does not wait for the joint to arrive; see
        :meth:`is_moving`.
        """
        joint = self.joint(joint_name)
        if not joint.min_deg <= angle_deg <= joint.max_deg:
            raise ValueError(
                f"joint {joint.name!r}: angle {angle_deg} deg is outside its limits "
                f"{joint.min_deg}..{joint.max_deg} deg"
            )
        if speed_dps is None:
            speed_dps = joint.max_speed_dps
        if not 0 < speed_dps <= joint.max_speed_dps:
            raise ValueError(
                f"joint {joint.name!r}: speed {speed_dps} deg/s is outside its limit "
                f"0 < speed <= {joint.max_speed_dps} deg/s"
            )
        units = speed_dps_to_maestro(joint, speed_dps)
        pulse_us = angle_to_us(joint, angle_deg)
        if us_to_quarter_us(pulse_us) == 0:
            raise ValueError(
                f"joint {joint.name!r}: angle {angle_deg} deg is a pulse of {pulse_us:g} us, "
                "which the Maestro takes as 0, 'off'; check the joint's min_us/max_us"
            )
        self._maestro.set_speed(joint.channel, units)
        self._maestro.set_target_us(joint.channel, pulse_us)
        # Commands get no reply; a query does. Its answer proves the controller heard the
        # move, and a controller that is silent (powered off, another program's port) fails
        # the move here, after the port's read timeout, instead of never.
        self._maestro.get_position_us(joint.channel)

    def position_deg(self, joint_name: str) -> float:
        """The angle in degrees the controller is driving ``joint_name`` to right now.

        Raises ServiceError if the channel is off (the controller sends no pulses, so the
        angle is unknown).
        """
        joint = self.joint(joint_name)
        pulse_us = self._maestro.get_position_us(joint.channel)
        if pulse_us == 0:
            raise ServiceError(
                f"joint {joint.name!r} (channel {joint.channel}) is off: no pulses are sent, "
                "so its angle is unknown"
            )
        return us_to_angle(joint, pulse_us)

    def is_moving(self) -> bool:
        """Whether any joint has yet to reach its target."""
        return self._maestro.is_moving()

    def home(self) -> None:
        """Move every joint to its ``home_deg`` at its speed limit."""
        for joint in self._joints.values():
            self.move(joint.name, joint.home_deg)

    def wait_until_still(self, timeout_s: float, *, poll_s: float = 0.02) -> None:
        """Wait on the clock until no joint moves; DeviceError after ``timeout_s`` seconds."""
        if timeout_s < 0 or poll_s <= 0:
            raise ValueError(f"timeout_s {timeout_s} and poll_s {poll_s} must be positive")
        deadline_s = self._clock.now() + timeout_s
        while self.is_moving():
            if self._clock.now() >= deadline_s:
                raise DeviceError(
                    errno.ETIMEDOUT,
                    f"joints {', '.join(self._joints)} still moving after {timeout_s} s",
                )
            self._clock.sleep(poll_s)
