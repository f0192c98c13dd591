"""The safety envelope at run time: every service call passes through it, and a watcher
between ticks stops the arms when a person comes too close or presses too hard.

It wraps the robot's services (:func:`with_envelope`), so trees, remote commands and
wizard-of-oz buttons all meet the same limits; no tree can reach the services around it.
A move the envelope refuses fails with :class:`SafetyRefusedError` and the reason; a loud
phrase is spoken at ``max_volume``, a bright color shown at ``max_brightness``, an arm near
a person moved at ``slow_speed_dps``. It fails safe: a sensor a rule reads that is offline,
stale or implausible counts as the worst case (someone at the chest, a hard press), and
arm moves are refused or slowed as the config's ``when_unsure`` says. Every refusal, slow
down and stop is published on the session stream with its rule and devices.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from concurrent.futures import CancelledError
from dataclasses import dataclass
from typing import Any

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import NOTHING, READINGS, Carries
from engine.colors import parse_color
from engine.errors import ServiceError
from engine.hardware.config import RobotConfig, SafetyConfig
from engine.hardware.safety_guards import (
    Guard,
    GuardReading,
    force_guards,
    range_guards,
    read_guard,
)
from engine.services.interfaces import Leds, Services, Servos, Speech
from engine.services.jobs import ImmediateJob, Job
from engine.session.events import SafetyAction, SafetyKind
from engine.session.stream import SessionStream


class SafetyRefusedError(ServiceError):
    """The safety envelope refused an action; the message says which rule and why (it
    starts with ``safety``), quoting the readings that decided (``carries``)."""

    def __init__(self, message: str, carries: Carries = NOTHING) -> None:
        super().__init__(message)
        self.carries = carries


@dataclass(frozen=True)
class Verdict:
    """Why the envelope holds the arms still or slows them: the ``rule`` (a field of
    ``safety:``), the ``devices`` it read, the reason in words, and whether it comes from
    readings that cannot be trusted (``unsure``)."""

    rule: str
    devices: tuple[str, ...]
    why: str
    unsure: bool = False

    @property
    def carries(self) -> Carries:
        """A rule that read sensors quotes what they read (a force, a distance)."""
        return frozenset({READINGS}) if self.devices else NOTHING


class SafetyEnvelope:
    """The rules of ``config`` read against the committed blackboard: the chest's range
    sensors (mm) and the side force pads (N), each reading trusted only when its device is
    working and the reading fresh and plausible (:mod:`engine.hardware.safety_guards`).
    What it decides is published on ``stream`` as
    :class:`~engine.session.events.SafetyAction`."""

    def __init__(
        self,
        config: SafetyConfig,
        blackboard: Blackboard,
        *,
        ranges: tuple[Guard, ...] = (),
        forces: tuple[Guard, ...] = (),
        stream: SessionStream | None = None,
    ) -> None:
        self.config = config
        self.blackboard = blackboard
        self.ranges = ranges
        self.forces = forces
        self.stream = stream

    @classmethod
    def of(
        cls, robot: RobotConfig, blackboard: Blackboard, stream: SessionStream | None = None
    ) -> SafetyEnvelope:
        """The envelope of a robot config, reading its range and force devices."""
        return cls(
            robot.safety,
            blackboard,
            ranges=range_guards(robot),
            forces=force_guards(robot),
            stream=stream,
        )

    def _read(self, guards: tuple[Guard, ...]) -> list[GuardReading]:
        now = self.blackboard.clock.now()
        return [read_guard(guard, self.blackboard, now) for guard in guards]

    def _doubts(self, rule: str, readings: list[GuardReading]) -> Verdict | None:
        doubtful = [r for r in readings if r.doubt is not None]
        if not doubtful:
            return None
        doubts = list(dict.fromkeys(str(r.doubt) for r in doubtful))  # a chip's pads: once
        devices = tuple(dict.fromkeys(r.guard.device for r in doubtful))
        they = "they cannot" if len(devices) > 1 else "it cannot"
        return Verdict(rule, devices, f"{'; '.join(doubts)}: {they} be trusted ({rule})", True)

    def _force_rule(self) -> Verdict | None:
        """What a trusted pad feels beyond ``stop_above_n`` says first; else a pad that
        cannot be trusted (only stricter, never laxer, than what the others feel)."""
        limit = self.config.stop_above_n
        if limit is None:
            return None
        readings = self._read(self.forces)
        for reading in readings:
            if reading.value is not None and reading.value > limit:
                return Verdict(
                    "stop_above_n",
                    (reading.guard.device,),
                    f"a side force of {reading.value:.1f} N is above {limit:g} N",
                )
        return self._doubts("stop_above_n", readings)

    def _distance_rule(self, rule: str, limit: float | None) -> Verdict | None:
        """What a trusted range sensor sees closer than ``limit`` says first; else a sensor
        that cannot be trusted."""
        if limit is None:
            return None
        readings = self._read(self.ranges)
        near = [r for r in readings if r.value is not None and r.value < limit]
        if not near:
            return self._doubts(rule, readings)
        nearest = min(near, key=lambda r: r.value or 0.0)
        return Verdict(
            rule,
            (nearest.guard.device,),
            f"something is {nearest.value:.0f} mm from the chest, closer than {limit:g} mm",
        )

    def hold_still(self) -> Verdict | None:
        """Why the arms must not move now (a hard press, someone very close, or a sensor
        that cannot be trusted when unsure moves are refused), or None."""
        rules = self.config
        for verdict in (
            self._force_rule(),
            self._distance_rule("still_within_mm", rules.still_within_mm),
        ):
            if verdict is not None and (not verdict.unsure or rules.when_unsure == "refuse"):
                return verdict
        return None

    def slow_down(self) -> Verdict | None:
        """Why an arm moves at most ``slow_speed_dps`` now (someone near, or a sensor that
        cannot be trusted when unsure moves are slowed), or None."""
        rules = self.config
        for verdict in (
            self._force_rule(),
            self._distance_rule("still_within_mm", rules.still_within_mm),
            self._distance_rule("slow_within_mm", rules.slow_within_mm),
        ):
            if verdict is not None and (verdict.unsure or verdict.rule == "slow_within_mm"):
                return verdict
        return None

    def refusal(self, joint: str, angle_deg: float) -> Verdict | None:
        """Why moving ``joint`` to ``angle_deg`` is refused now, or None."""
        limits = self.config.joint_limits.get(joint)
        if limits is not None and not limits[0] <= angle_deg <= limits[1]:
            return Verdict(
                "joint_limits",
                (),
                f"{joint} may move within {limits[0]:g}..{limits[1]:g} deg only, "
                f"not to {angle_deg:g} deg",
            )
        if joint in self.config.arms:
            verdict = self.hold_still()
            if verdict is not None:
                return Verdict(verdict.rule, verdict.devices, f"{verdict.why}: the arms stay still")
        return None

    def speed_dps(self, joint: str, speed_dps: float | None) -> tuple[float | None, Verdict | None]:
        """The speed a move of ``joint`` may have now (slower near a person, or when a
        sensor cannot be trusted), and why it was slowed (None: as asked)."""
        if joint not in self.config.arms:
            return speed_dps, None
        verdict = self.slow_down()
        slow = self.config.slow_speed_dps
        if verdict is None or (speed_dps is not None and speed_dps <= slow):
            return speed_dps, None
        return slow, verdict

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

    def tell(self, action: SafetyKind, joint: str, verdict: Verdict) -> None:
        """Publish what the envelope did to a move of ``joint``."""
        if self.stream is not None:
            now = self.blackboard.clock.now()
            self.stream.publish(
                SafetyAction(
                    now, action, joint, verdict.rule, verdict.devices, verdict.why, verdict.carries
                )
            )


class EnvelopedSpeech:
    def __init__(self, inner: Speech, envelope: SafetyEnvelope) -> None:
        self.inner, self.envelope = inner, envelope

    def say(self, text: str, *, volume: float | None = None, interruptible: bool = True) -> Job:
        volume = self.envelope.volume(volume)
        return self.inner.say(text, volume=volume, interruptible=interruptible)


class EnvelopedLeds:
    def __init__(self, inner: Leds, envelope: SafetyEnvelope) -> None:
        self.inner, self.envelope = inner, envelope

    def set_color(self, color: str, *, seconds: float | None = None) -> Job:
        return self.inner.set_color(self.envelope.color(color), seconds=seconds)


class StoppableMove:
    """A servo move the watcher can stop (it then fails with the safety reason); a move
    cancelled half-way (its tree halted) stops the joint where it is, as the watcher does:
    a cancelled job alone would not stop a servo already told where to go. ``speed_dps``
    is the speed it was sent at (None: the joint's full speed)."""

    def __init__(
        self, job: Job, hold_still: Callable[[], None], speed_dps: float | None = None
    ) -> None:
        self.job = job
        self.hold_still = hold_still
        self.speed_dps = speed_dps
        self.stopped: SafetyRefusedError | None = None

    def stop(self, why: str, carries: Carries = NOTHING) -> None:
        self.stopped = SafetyRefusedError(f"safety stopped it: {why}", carries)
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


class RestWhenSafe:
    """A move back to rest that the envelope cannot allow now: made by the watcher as soon
    as it can (the arm is not left away from rest for good); a newer move of the joint, or
    a cancel, drops it."""

    def __init__(self, start: Callable[[], Job]) -> None:
        self._start = start
        self.job: Job | None = None
        self.dropped = False

    def begin(self) -> None:
        if not self.dropped and self.job is None:
            self.job = self._start()

    def done(self) -> bool:
        return self.dropped or (self.job is not None and self.job.done())

    def error(self) -> BaseException | None:
        if self.job is not None:
            return self.job.error()
        return CancelledError("dropped before the envelope allowed it") if self.dropped else None

    def result(self) -> Any:
        return self.job.result() if self.job is not None else None

    def cancel(self) -> None:
        if self.job is not None:
            self.job.cancel()
        self.dropped = True


class EnvelopedServos:
    """Moves checked and slowed by the envelope; the moves under way and the moves back
    to rest still to make, for the watcher."""

    def __init__(self, inner: Servos, envelope: SafetyEnvelope) -> None:
        self.inner, self.envelope = inner, envelope
        self.moving: dict[str, StoppableMove] = {}
        self.resting: dict[str, tuple[float, RestWhenSafe]] = {}

    def move(self, joint: str, angle_deg: float, *, speed_dps: float | None = None) -> Job:
        waiting = self.resting.pop(joint, None)
        if waiting is not None and waiting[1].job is None:
            waiting[1].cancel()  # a newer move of the joint: the rest it waited for is moot
        refused = self.envelope.refusal(joint, angle_deg)
        if refused is not None and (angle_deg, speed_dps) == self.inner.rest_pose(joint):
            rest = RestWhenSafe(lambda: self.move(joint, angle_deg, speed_dps=speed_dps))
            self.resting[joint] = (angle_deg, rest)
            waits = f"{refused.why}: it goes back to rest once it may"
            self.envelope.tell("held", joint, dataclasses.replace(refused, why=waits))
            return rest
        if refused is not None:
            self.envelope.tell("refused", joint, refused)
            refusal = SafetyRefusedError(f"safety: {refused.why}", refused.carries)
            return ImmediateJob(error=refusal)
        speed, slowed = self.envelope.speed_dps(joint, speed_dps)
        started = self.inner.move(joint, angle_deg, speed_dps=speed)
        if slowed is not None:
            moves = f"{slowed.why}: the arm moves at {speed:g} deg/s"
            self.envelope.tell("slowed", joint, dataclasses.replace(slowed, why=moves))
        move = StoppableMove(started, lambda: self.inner.stop(joint), speed)
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
    under way is stopped where the arm is (its node then fails); when a sensor cannot be
    trusted and unsure moves are slowed, every arm move faster than ``slow_speed_dps`` is
    stopped. Each stop is published as a ``stopped``
    :class:`~engine.session.events.SafetyAction`."""

    def __init__(self, servos: EnvelopedServos, envelope: SafetyEnvelope) -> None:
        self.servos = servos
        self.envelope = envelope
        self.stops = 0

    def __call__(self, now_s: float) -> None:
        for joint, (angle_deg, rest) in list(self.servos.resting.items()):
            if rest.dropped:
                self.servos.resting.pop(joint, None)
            elif self.envelope.refusal(joint, angle_deg) is None:  # now it may: back to rest
                self.servos.resting.pop(joint, None)
                rest.begin()
        moving = [
            (joint, move)
            for joint, move in self.servos.moving.items()
            if joint in self.envelope.config.arms and not move.done()
        ]
        if not moving:
            return
        verdict = self.envelope.hold_still()
        slow = self.envelope.config.slow_speed_dps
        if verdict is None:
            unsure = self.envelope.slow_down()
            if unsure is None or not unsure.unsure:
                return
            verdict = unsure
            moving = [(j, m) for j, m in moving if m.speed_dps is None or m.speed_dps > slow]
        for joint, move in moving:
            self.servos.stop(joint)
            self.servos.moving.pop(joint)
            move.stop(verdict.why, verdict.carries)
            self.stops += 1
            self.envelope.tell("stopped", joint, verdict)
