"""The safety envelope at run time: every service call passes through it, and a watcher
between ticks stops the arms when a person comes too close or presses too hard.

It wraps the robot's services (:func:`with_envelope`), so trees, remote commands and
wizard-of-oz buttons all meet the same limits; no tree can reach the services around it.
A move the envelope refuses fails with :class:`SafetyRefusedError` and the reason (the
timeline prints it); a loud phrase is spoken at ``max_volume``, a bright color shown at
``max_brightness``, an arm near a person moved at ``slow_speed_dps``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

from engine.blackboard.board import Blackboard
from engine.colors import parse_color
from engine.errors import ServiceError
from engine.hardware.config import RobotConfig, SafetyConfig
from engine.services.interfaces import Leds, Services, Servos, Speech
from engine.services.jobs import ImmediateJob, Job


class SafetyRefusedError(ServiceError):
    """The safety envelope refused an action; the message says which rule and why."""


class SafetyEnvelope:
    """The rules of ``config`` read against the committed blackboard: the chest's range
    sensors (``range_keys``, mm) and the side force pads (``force_keys``, N)."""

    def __init__(
        self,
        config: SafetyConfig,
        blackboard: Blackboard,
        *,
        range_keys: tuple[str, ...] = (),
        force_keys: tuple[str, ...] = (),
    ) -> None:
        self.config = config
        self.blackboard = blackboard
        self.range_keys = range_keys
        self.force_keys = force_keys

    @classmethod
    def of(cls, robot: RobotConfig, blackboard: Blackboard) -> SafetyEnvelope:
        """The envelope of a robot config, reading its range and force devices' keys."""
        ranges = tuple(d.keys["range"] for d in robot.with_role("range") if "range" in d.keys)
        forces = tuple(pad.key for d in robot.with_role("force") for pad in d.pads)
        return cls(robot.safety, blackboard, range_keys=ranges, force_keys=forces)

    def _numbers(self, keys: tuple[str, ...]) -> list[float]:
        values = (self.blackboard.get(key) for key in keys)
        return [
            float(v)
            for v in values
            if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
        ]

    def nearest_mm(self) -> float | None:
        """The closest thing the chest's range sensors see, mm (None: nothing in range)."""
        seen = self._numbers(self.range_keys)
        return min(seen) if seen else None

    def side_force_n(self) -> float | None:
        """The larger of the side pads' forces, N."""
        felt = self._numbers(self.force_keys)
        return max(felt) if felt else None

    def hold_still(self) -> str | None:
        """Why the arms must not move now (a hard press, someone very close), or None."""
        rules = self.config
        force = self.side_force_n()
        if rules.stop_above_n is not None and force is not None and force > rules.stop_above_n:
            return f"a side force of {force:.1f} N is above {rules.stop_above_n:g} N"
        near = self.nearest_mm()
        if rules.still_within_mm is not None and near is not None and near < rules.still_within_mm:
            return (
                f"something is {near:.0f} mm from the chest, closer than "
                f"{rules.still_within_mm:g} mm"
            )
        return None

    def refusal(self, joint: str, angle_deg: float) -> str | None:
        """Why moving ``joint`` to ``angle_deg`` is refused now, or None."""
        limits = self.config.joint_limits.get(joint)
        if limits is not None and not limits[0] <= angle_deg <= limits[1]:
            return (
                f"safety: {joint} may move within {limits[0]:g}..{limits[1]:g} deg only, "
                f"not to {angle_deg:g} deg"
            )
        if joint in self.config.arms:
            why = self.hold_still()
            if why is not None:
                return f"safety: {why}: the arms stay still"
        return None

    def speed_dps(self, joint: str, speed_dps: float | None) -> float | None:
        """The speed a move of ``joint`` may have now (slower near a person)."""
        rules = self.config
        near = self.nearest_mm()
        if (
            joint in rules.arms
            and rules.slow_within_mm is not None
            and near is not None
            and near < rules.slow_within_mm
        ):
            return min(speed_dps if speed_dps is not None else math.inf, rules.slow_speed_dps)
        return speed_dps

    def volume(self, volume: float | None) -> float | None:
        """``volume`` no louder than ``max_volume`` (None: the robot's default, capped)."""
        limit = self.config.max_volume
        if limit >= 1.0:
            return volume
        return min(volume if volume is not None else 1.0, limit)

    def color(self, color: str) -> str:
        """``color`` dimmed to ``max_brightness`` (as #RRGGBB when dimmed)."""
        limit = self.config.max_brightness
        if limit >= 1.0 or color == "off":
            return color
        try:
            rgb = parse_color(color)
        except ValueError:
            return color  # the LED service names the unknown color
        if max(rgb) <= limit:
            return color
        scale = limit / max(rgb)
        return "#" + "".join(f"{round(part * scale * 255):02X}" for part in rgb)

    def moves_always_refused(self, joint: str, angle_deg: float) -> str | None:
        """Why a move of ``joint`` to ``angle_deg`` can never be made (for validate)."""
        limits = self.config.joint_limits.get(joint)
        if limits is not None and not limits[0] <= angle_deg <= limits[1]:
            return self.refusal(joint, angle_deg)
        return None


class EnvelopedSpeech:
    def __init__(self, inner: Speech, envelope: SafetyEnvelope) -> None:
        self.inner, self.envelope = inner, envelope

    def say(self, text: str, *, volume: float | None = None) -> Job:
        return self.inner.say(text, volume=self.envelope.volume(volume))


class EnvelopedLeds:
    def __init__(self, inner: Leds, envelope: SafetyEnvelope) -> None:
        self.inner, self.envelope = inner, envelope

    def set_color(self, color: str, *, seconds: float | None = None) -> Job:
        return self.inner.set_color(self.envelope.color(color), seconds=seconds)


class StoppableMove:
    """A servo move the watcher can stop (it then fails with the safety reason); a move
    cancelled half-way (its tree halted) stops the joint where it is, as the watcher does:
    a cancelled job alone would not stop a servo already told where to go."""

    def __init__(self, job: Job, hold_still: Callable[[], None]) -> None:
        self.job = job
        self.hold_still = hold_still
        self.stopped: SafetyRefusedError | None = None

    def stop(self, why: str) -> None:
        self.stopped = SafetyRefusedError(f"safety stopped it: {why}")
        self.job.cancel()

    def done(self) -> bool:
        return self.stopped is not None or self.job.done()

    def error(self) -> BaseException | None:
        return self.stopped or self.job.error()

    def result(self) -> Any:
        return self.job.result()

    def cancel(self) -> None:
        if not self.done():
            self.hold_still()
        self.job.cancel()


class EnvelopedServos:
    """Moves checked and slowed by the envelope; the moves under way, for the watcher."""

    def __init__(self, inner: Servos, envelope: SafetyEnvelope) -> None:
        self.inner, self.envelope = inner, envelope
        self.moving: dict[str, StoppableMove] = {}

    def move(self, joint: str, angle_deg: float, *, speed_dps: float | None = None) -> Job:
        why = self.envelope.refusal(joint, angle_deg)
        if why is not None:
            return ImmediateJob(error=SafetyRefusedError(why))
        speed = self.envelope.speed_dps(joint, speed_dps)
        started = self.inner.move(joint, angle_deg, speed_dps=speed)
        move = StoppableMove(started, lambda: self.inner.stop(joint))
        self.moving[joint] = move
        return move

    def rest_pose(self, joint: str) -> tuple[float, float | None]:
        return self.inner.rest_pose(joint)

    def stop(self, joint: str) -> None:
        self.inner.stop(joint)


def with_envelope(services: Services, envelope: SafetyEnvelope) -> Services:
    """``services`` with every speech, LED and servo call passing through ``envelope``."""
    return dataclasses.replace(
        services,
        speech=EnvelopedSpeech(services.speech, envelope),
        leds=EnvelopedLeds(services.leds, envelope),
        servos=EnvelopedServos(services.servos, envelope),
    )


class EnvelopeWatcher:
    """A scheduler hook: between ticks, when the arms must hold still, every arm move
    under way is stopped where the arm is (its node then fails), and ``tell(who, what)``
    hears it once per stop."""

    def __init__(
        self,
        servos: EnvelopedServos,
        envelope: SafetyEnvelope,
        tell: Callable[[str, str], Any] = lambda who, what: None,
    ) -> None:
        self.servos = servos
        self.envelope = envelope
        self.tell = tell
        self.stops = 0

    def __call__(self, now_s: float) -> None:
        moving = [
            joint
            for joint, job in self.servos.moving.items()
            if joint in self.envelope.config.arms and not job.done()
        ]
        if not moving:
            return
        why = self.envelope.hold_still()
        if why is None:
            return
        for joint in moving:
            self.servos.stop(joint)
            self.servos.moving.pop(joint).stop(why)
            self.stops += 1
            self.tell("safety", f"stops {joint} where it is: {why}")
