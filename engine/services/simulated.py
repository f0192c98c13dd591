"""Services without hardware: they take realistic time on the clock and remember calls.

``vest run`` uses them on the simulated vest until real speech, LED and servo services
are configured; the test harness uses them as recording fakes. Each keeps ``calls`` and
can be told to fail its next call (``fail_next = "why"``) to test failure paths.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.blackboard.catalogue import NOTHING, TEMPERATURE_C, TEMPERATURE_F, Carries
from engine.clock import Clock
from engine.errors import ServiceError
from engine.services.interfaces import Services
from engine.services.jobs import ImmediateJob, Job, TimedJob


class _Recording:
    def __init__(self) -> None:
        self.calls: list[tuple[Any, ...]] = []
        self.fail_next: str | None = None

    def _refused(self) -> Job | None:
        if self.fail_next is None:
            return None
        why, self.fail_next = self.fail_next, None
        return ImmediateJob(error=ServiceError(why))


class SimulatedSpeech(_Recording):
    """Speaks into ``calls``; a phrase takes ``seconds_per_word`` per word (0: instant)."""

    def __init__(self, clock: Clock, *, seconds_per_word: float = 0.0) -> None:
        super().__init__()
        self.clock = clock
        self.seconds_per_word = seconds_per_word

    def say(self, text: str, *, volume: float | None = None, interruptible: bool = True) -> Job:
        self.calls.append((text, volume))
        return self._refused() or TimedJob(self.clock, self.seconds_per_word * len(text.split()))


class SimulatedLeds(_Recording):
    """Remembers the face color; ``seconds`` lights it for that long, then off."""

    def __init__(self, clock: Clock) -> None:
        super().__init__()
        self.clock = clock
        self._color = "off"
        self._until_s: float | None = None

    @property
    def color(self) -> str:
        if self._until_s is not None and self.clock.now() >= self._until_s:
            self._color, self._until_s = "off", None
        return self._color

    def set_color(self, color: str, *, seconds: float | None = None) -> Job:
        self.calls.append((color, seconds))
        refused = self._refused()
        if refused:
            return refused
        self._color = color
        self._until_s = None if seconds is None else self.clock.now() + seconds
        return TimedJob(self.clock, seconds or 0.0)


class SimulatedServos(_Recording):
    """Joints that move at their speed; a move takes distance / speed seconds."""

    def __init__(self, clock: Clock, *, default_speed_dps: float = 0.0) -> None:
        super().__init__()
        self.clock = clock
        self.default_speed_dps = default_speed_dps
        self.angles_deg: dict[str, float] = {}
        self._moves: dict[str, _ServoMove] = {}

    def move(self, joint: str, angle_deg: float, *, speed_dps: float | None = None) -> Job:
        self.calls.append((joint, angle_deg, speed_dps))
        refused = self._refused()
        if refused:
            return refused
        start = self.angles_deg.get(joint, 0.0)
        self.angles_deg[joint] = angle_deg
        speed = speed_dps or self.default_speed_dps
        seconds = abs(angle_deg - start) / speed if speed > 0 else 0.0
        move = self._moves[joint] = _ServoMove(self, joint, start, angle_deg, seconds)
        return move

    def stop(self, joint: str) -> None:
        """The joint stays where its move under way has got to."""
        self.calls.append((joint, "stop"))
        move = self._moves.pop(joint, None)
        if move is not None:
            move.cancel()

    def rest_pose(self, joint: str) -> tuple[float, float | None]:
        """Every simulated joint rests at 0 deg, going there at a third of the default speed."""
        return 0.0, (self.default_speed_dps / 3) or None


class _ServoMove(TimedJob):
    """A move that, cancelled half-way, leaves the joint where it had got to."""

    def __init__(
        self, servos: SimulatedServos, joint: str, start_deg: float, end_deg: float, seconds: float
    ) -> None:
        super().__init__(servos.clock, seconds)
        self._servos = servos
        self._joint = joint
        self._start_deg = start_deg
        self._end_deg = end_deg
        self._seconds = seconds

    def cancel(self) -> None:
        if self.done():
            return
        left_s = self.finishes_at_s - self._clock.now()
        moved = 1.0 - left_s / self._seconds if self._seconds > 0 else 1.0
        self._servos.angles_deg[self._joint] = (
            self._start_deg + (self._end_deg - self._start_deg) * moved
        )
        super().cancel()


class SimulatedSensors(_Recording):
    """Answers on-request reads from ``readers``: sensor name -> function giving key values."""

    def __init__(self, readers: dict[str, Callable[[], dict[str, Any]]] | None = None) -> None:
        super().__init__()
        self.readers = readers if readers is not None else {}

    def read(self, sensor: str) -> Job:
        self.calls.append((sensor,))
        refused = self._refused()
        if refused:
            return refused
        reader = self.readers.get(sensor)
        if reader is None:
            known = ", ".join(sorted(self.readers)) or "none"
            return ImmediateJob(error=ServiceError(f"no sensor {sensor!r} (known: {known})"))
        return ImmediateJob(reader())


class SimulatedIot(_Recording):
    """Keeps reported results in ``calls`` as (command_id, status, result)."""

    def report(
        self, command_id: str, status: str, result: Any = None, *, carries: Carries = NOTHING
    ) -> Job:
        self.calls.append((command_id, status, result))
        return self._refused() or ImmediateJob()


def simulated_services(
    clock: Clock,
    *,
    readers: dict[str, Callable[[], dict[str, Any]]] | None = None,
    realistic: bool = False,
) -> Services:
    """A full set of simulated services; ``realistic`` gives speech and servo moves duration."""
    return Services(
        speech=SimulatedSpeech(clock, seconds_per_word=0.3 if realistic else 0.0),
        leds=SimulatedLeds(clock),
        servos=SimulatedServos(clock, default_speed_dps=120.0 if realistic else 0.0),
        sensors=SimulatedSensors(readers),
        iot=SimulatedIot(),
    )


def fahrenheit(celsius: float) -> float:
    """Degrees Celsius to Fahrenheit."""
    return celsius * 9.0 / 5.0 + 32.0


def temperature_reading(celsius: float) -> dict[str, float]:
    """The blackboard values a temperature read produces."""
    return {TEMPERATURE_C: celsius, TEMPERATURE_F: fahrenheit(celsius)}
