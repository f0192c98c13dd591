"""Services on the vest's drivers: LEDs, servo joints, temperature and ultrasound on request.

They implement :mod:`engine.services.interfaces` (speech stays simulated for now). Every
method returns a :class:`~engine.services.jobs.Job` at once; the work is one or a few
transactions on the device's bus manager at :attr:`~engine.drivers.bus_manager.Priority.REQUEST`
priority, ahead of routine polls. With ``threaded`` bus managers the transactions run on the
bus's worker and a job is done when its future is; inline they have run by the time the
method returns.

- :class:`HardwareLeds`: every LED of the config's PCA9685 in one color; with ``seconds``
  the LEDs go dark again when the hook (``leds(now_s)``, a scheduler hook) sees the time,
  tried again until the chip took it. A rebuilt driver (after a failure: a replugged chip
  starts dark) lights the color the LEDs should show.
- :class:`HardwareServos`: joints in degrees on the Maestro; a move beyond a joint's limits
  is a failed job that says so, and nothing is sent. The job lasts as long as the move
  takes at its speed.
- :class:`HardwareSensors`: ``read("temperature")`` is one MCP9808 register read;
  ``read("ultrasound")`` commands an SRF02 ranging and comes back for the result once the
  ranging time (66 ms) has passed on the clock, never waiting for it in a tick.

Drivers are made inside the first transaction that needs them, on the bus itself, and
made again after a failure (a replugged chip starts from power-on).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import CancelledError, Future
from typing import Any, Generic, TypeVar

from engine.clock import Clock
from engine.colors import parse_color
from engine.drivers.bus_manager import DeviceHandle, Priority
from engine.drivers.mcp9808 import MCP9808, celsius_to_fahrenheit
from engine.drivers.pca9685 import PCA9685
from engine.drivers.rgb_leds import ALL, RgbLeds
from engine.drivers.servo_joints import Joint, ServoJoints
from engine.drivers.srf02 import MAX_POLLS, POLL_INTERVAL_S, RANGING_TIME_S, SRF02
from engine.errors import ServiceError
from engine.hardware.branching_clock import branch_of
from engine.hardware.config import DeviceConfig
from engine.services.jobs import ImmediateJob, Job

D = TypeVar("D")
T = TypeVar("T")

ON_REQUEST_SENSORS = ("temperature", "ultrasound")
LED_OFF_RETRY_S = 0.5
"""Seconds between two tries to turn the LEDs off when the chip did not take it."""


class DriverSlot(Generic[D]):
    """A driver made on the bus inside the first transaction that needs it.

    ``make(bus)`` builds it (identity check, init); a transaction that fails drops it, so
    the next one starts from a fresh driver.
    """

    def __init__(self, make: Callable[[Any], D]) -> None:
        self._make = make
        self.driver: D | None = None

    def get(self, bus: Any) -> D:
        if self.driver is None:
            self.driver = self._make(bus)
        return self.driver

    def run(self, bus: Any, work: Callable[[D], T]) -> T:
        try:
            return work(self.get(bus))
        except Exception:
            self.driver = None
            raise


class _OnDevice(Generic[D]):
    """A device a service drives: its handle, its driver slot, transactions on request."""

    def __init__(
        self,
        device: DeviceConfig,
        handle: DeviceHandle[Any],
        clock: Clock,
        make: Callable[[Any], D],
    ) -> None:
        self.device = device
        self.handle = handle
        self.clock = clock
        self.slot: DriverSlot[D] = DriverSlot(make)

    def submit(self, work: Callable[[D], T]) -> Future[T]:
        """Run ``work(driver)`` as one transaction, ahead of polls."""
        with branch_of(self.clock):
            return self.handle.submit(
                lambda bus: self.slot.run(bus, work), priority=Priority.REQUEST
            )

    def call(self, work: Callable[[D], T], timeout_s: float | None = 2.0) -> T:
        """Run ``work(driver)`` and wait for it (start-up, ``vest devices``)."""
        return self.handle.call(lambda bus: self.slot.run(bus, work), timeout_s=timeout_s)

    def connect(self) -> None:
        """Make the driver now (identity check and init); raises what that raised."""
        self.call(lambda driver: None)


# -- jobs ------------------------------------------------------------------------------------
class FutureResultJob:
    """A transaction's future as a Job, its result passed through ``convert``."""

    def __init__(self, future: Future[Any], convert: Callable[[Any], Any] = lambda v: v) -> None:
        self._future = future
        self._convert = convert
        self._cancelled = False

    def done(self) -> bool:
        return self._cancelled or self._future.done()

    def error(self) -> BaseException | None:
        if self._cancelled:
            return CancelledError("cancelled")
        if not self._future.done():
            return None
        if self._future.cancelled():
            return CancelledError("cancelled")
        return self._future.exception()

    def result(self) -> Any:
        if self.error() is not None or not self._future.done():
            return None
        return self._convert(self._future.result())

    def cancel(self) -> None:
        if not self.done():
            self._future.cancel()
            self._cancelled = True


class TimedFutureJob(FutureResultJob):
    """A command's future, then ``seconds`` on the clock (lit for a while, a servo moving)."""

    def __init__(self, future: Future[Any], clock: Clock, seconds: float) -> None:
        super().__init__(future)
        self._clock = clock
        self.finishes_at_s = clock.now() + max(0.0, seconds)

    def done(self) -> bool:
        if not super().done():
            return False
        if self.error() is not None:
            return True
        return self._clock.now() >= self.finishes_at_s


# -- LEDs --------------------------------------------------------------------------------------
class HardwareLeds:
    """The face LEDs on the config's PCA9685: :class:`~engine.services.interfaces.Leds`.

    Also a scheduler hook: ``leds(now_s)`` turns the LEDs off when a ``seconds`` ran out,
    and tries again every :data:`LED_OFF_RETRY_S` until the chip took it.
    """

    def __init__(self, device: DeviceConfig, handle: DeviceHandle[Any], clock: Clock) -> None:
        self.device = device
        self.clock = clock
        self._on = _OnDevice(device, handle, clock, self._make)
        self.color = "off"
        """The color the LEDs should show (what the trees asked for last)."""
        self._off_at_s: float | None = None  # kept until an "off" went through
        self._off: Future[None] | None = None  # the "off" on its way to the chip
        self._retry_at_s = float("-inf")
        self.pwm: PCA9685 | None = None

    def _make(self, bus: Any) -> RgbLeds:
        """A new driver (the chip starts dark), showing the color the LEDs should show."""
        assert self.device.address is not None
        pwm = PCA9685(bus, address=self.device.address, clock=self.clock)
        pwm.set_frequency_hz(self.device.options["frequency_hz"])
        self.pwm = pwm
        leds = RgbLeds(pwm, self.device.leds, common_anode=self.device.options["common_anode"])
        if self.color != "off":
            leds.set_color(ALL, parse_color(self.color))
        return leds

    @property
    def handle(self) -> DeviceHandle[Any]:
        return self._on.handle

    def connect(self) -> None:
        """Start the PCA9685 now (all LEDs dark); raises what its driver raised."""
        self._on.connect()

    def set_color(self, color: str, *, seconds: float | None = None) -> Job:
        """Light every LED in ``color`` (a name or #RRGGBB); dark again after ``seconds``."""
        try:
            rgb = parse_color(color)
        except ValueError as error:
            return ImmediateJob(error=ServiceError(str(error)))
        if seconds is not None and seconds < 0:
            return ImmediateJob(error=ServiceError(f"LED seconds must not be negative: {seconds}"))
        future = self._on.submit(lambda leds: leds.set_color(ALL, rgb))
        self.color = color
        self._off_at_s = None if seconds is None else self.clock.now() + seconds
        self._off = None  # an "off" still on its way is overtaken by this color
        self._retry_at_s = float("-inf")
        return TimedFutureJob(future, self.clock, seconds or 0.0)

    def __call__(self, now_s: float) -> None:
        """Scheduler hook: the LEDs go dark when their time is up, tried until they are."""
        if self._off_at_s is None:
            return
        if self._off is None:
            if now_s + 1e-9 < max(self._off_at_s, self._retry_at_s):
                return
            self.color = "off"
            self._off = self._on.submit(lambda leds: leds.off())
        if not self._off.done():
            return  # on the bus worker; the next call looks again
        failed = self._off.cancelled() or self._off.exception() is not None
        self._off = None
        if failed:  # still lit: keep the deadline, try again a little later
            self._retry_at_s = now_s + LED_OFF_RETRY_S
        else:
            self._off_at_s = None

    def read_now(self) -> str:
        """What the PCA9685 says (for ``vest devices``): its PWM frequency."""
        self._on.connect()
        assert self.pwm is not None
        pwm = self.pwm
        frequency_hz = self._on.call(lambda leds: pwm.frequency_hz)
        return f"PWM {frequency_hz:.0f} Hz, LEDs {', '.join(self.device.leds)}"


# -- servos ----------------------------------------------------------------------------------
class HardwareServos:
    """The robot's joints on the Maestro: :class:`~engine.services.interfaces.Servos`.

    ``handle`` is the Maestro's claim on its serial bus manager, whose bus object is the
    :class:`~engine.drivers.maestro.Maestro`.
    """

    def __init__(self, device: DeviceConfig, handle: DeviceHandle[Any], clock: Clock) -> None:
        self.device = device
        self.clock = clock
        self.joints: dict[str, Joint] = {joint.name: joint for joint in device.joints}
        self._on = _OnDevice(
            device, handle, clock, lambda maestro: ServoJoints(maestro, device.joints, clock=clock)
        )
        self.angles_deg: dict[str, float] = {}

    @property
    def handle(self) -> DeviceHandle[Any]:
        return self._on.handle

    def home(self) -> None:
        """Send every joint to its home angle now (start-up); raises what the driver raised."""
        self._on.call(lambda joints: joints.home())
        self.angles_deg = {name: joint.home_deg for name, joint in self.joints.items()}

    def refusal(self, joint_name: str, angle_deg: float, speed_dps: float | None) -> str | None:
        """Why a move may not be made (unknown joint, beyond its limits), or None."""
        joint = self.joints.get(joint_name)
        if joint is None:
            known = ", ".join(self.joints) or "none"
            return f"unknown joint {joint_name!r}; known joints: {known}"
        if not joint.min_deg <= angle_deg <= joint.max_deg:
            return (
                f"joint {joint.name!r}: angle {angle_deg:g} deg is outside its limits "
                f"{joint.min_deg:g}..{joint.max_deg:g} deg"
            )
        if speed_dps is not None and not 0 < speed_dps <= joint.max_speed_dps:
            return (
                f"joint {joint.name!r}: speed {speed_dps:g} deg/s is outside its limit "
                f"0 < speed <= {joint.max_speed_dps:g} deg/s"
            )
        return None

    def move(self, joint: str, angle_deg: float, *, speed_dps: float | None = None) -> Job:
        """Move ``joint`` to ``angle_deg`` at ``speed_dps`` (default: the joint's limit).

        A move beyond the joint's limits fails at once with the reason; nothing is sent.
        The job is done when the move has had its time (distance / speed).
        """
        why = self.refusal(joint, angle_deg, speed_dps)
        if why is not None:
            return ImmediateJob(error=ServiceError(why))
        limits = self.joints[joint]
        speed = speed_dps if speed_dps is not None else limits.max_speed_dps
        start = self.angles_deg.get(joint, limits.home_deg)
        future = self._on.submit(lambda joints: joints.move(joint, angle_deg, speed))
        self.angles_deg[joint] = angle_deg
        return TimedFutureJob(future, self.clock, abs(angle_deg - start) / speed)

    def position_deg(self, joint: str) -> float:
        """The angle the Maestro drives ``joint`` to now (a query; waits for the reply)."""
        return self._on.call(lambda joints: joints.position_deg(joint))

    def read_now(self) -> str:
        """Each joint's angle as the Maestro reports it (for ``vest devices``)."""
        parts = []
        for name in self.joints:
            try:
                parts.append(f"{name} {self.position_deg(name):.0f} deg")
            except ServiceError:
                parts.append(f"{name} off")
        return ", ".join(parts)


# -- sensors read on request -----------------------------------------------------------------------
class TemperatureSensor:
    """The MCP9808: one register read per request."""

    def __init__(self, device: DeviceConfig, handle: DeviceHandle[Any], clock: Clock) -> None:
        self.device = device
        self.keys = device.keys
        self._on = _OnDevice(device, handle, clock, self._make)

    def _make(self, bus: Any) -> MCP9808:
        assert self.device.address is not None
        return MCP9808(
            bus, address=self.device.address, resolution_c=self.device.options["resolution_c"]
        )

    def connect(self) -> None:
        self._on.connect()

    def read(self) -> Job:
        future = self._on.submit(lambda sensor: sensor.read_temperature_c())
        return FutureResultJob(future, self.reading)

    def reading(self, celsius: float) -> dict[str, float]:
        """The blackboard values of one reading."""
        return {
            self.keys["celsius"]: celsius,
            self.keys["fahrenheit"]: celsius_to_fahrenheit(celsius),
        }

    def read_now(self) -> str:
        return f"{self._on.call(lambda sensor: sensor.read_temperature_c()):.2f} degC"


class UltrasoundSensor:
    """The SRF02: a ranging is commanded, and its result read once the ranging time passed."""

    def __init__(self, device: DeviceConfig, handle: DeviceHandle[Any], clock: Clock) -> None:
        self.device = device
        self.clock = clock
        self.key = device.keys["range"]
        self._on = _OnDevice(device, handle, clock, self._make)
        self._ranging: _Ranging | None = None

    def _make(self, bus: Any) -> SRF02:
        assert self.device.address is not None
        return SRF02(bus, address=self.device.address, clock=self.clock)

    def connect(self) -> None:
        self._on.connect()

    def read(self) -> Job:
        """A job done once the ranging's result is read (66 ms or so later)."""
        if self._ranging is None or self._ranging.step():
            self._ranging = _Ranging(self._on, self.clock)
        return UltrasoundJob(self._ranging, self.reading)

    def reading(self, distance_cm: int) -> dict[str, float | None]:
        """The blackboard value of one result (0 cm, no echo: nothing in range, None)."""
        return {self.key: float(distance_cm) if distance_cm > 0 else None}

    def read_now(self) -> str:
        distance_cm = self._on.call(lambda sensor: sensor.read_range_cm())
        return f"{distance_cm} cm" if distance_cm else "nothing in range"


class _Ranging:
    """One SRF02 ranging: start, wait the ranging time on the clock, then read the result."""

    def __init__(self, on: _OnDevice[SRF02], clock: Clock) -> None:
        self._on = on
        self._clock = clock
        self._start = on.submit(lambda sensor: sensor.start_ranging())
        self.ready_at_s = clock.now() + RANGING_TIME_S
        self.give_up_at_s = self.ready_at_s + MAX_POLLS * POLL_INTERVAL_S
        self._result: Future[int | None] | None = None
        self.finished = False
        self.distance_cm: int | None = None
        self.error: BaseException | None = None

    def step(self) -> bool:
        """Move the ranging on without waiting; True once it finished (or failed)."""
        if self.finished:
            return True
        if not self._start.done():
            return False
        error = self._start.exception()
        if error is not None:
            return self._finish(error=error)
        now_s = self._clock.now()
        if now_s < self.ready_at_s:
            return False  # the chip does not listen while it ranges: no bus traffic
        if self._result is None:
            self._result = self._on.submit(
                lambda sensor: sensor.read_result_cm() if sensor.result_ready() else None
            )
        if not self._result.done():
            return False
        error = self._result.exception()
        if error is not None:
            return self._finish(error=error)
        distance_cm = self._result.result()
        if distance_cm is None:
            if now_s >= self.give_up_at_s:
                return self._finish(
                    error=ServiceError(
                        f"SRF02 {self._on.device.name!r} still ranging "
                        f"{now_s - self.ready_at_s + RANGING_TIME_S:.3f} s after the command"
                    )
                )
            self._result = None  # ask again on a later step
            return False
        self.distance_cm = distance_cm
        return self._finish()

    def _finish(self, *, error: BaseException | None = None) -> bool:
        self.error = error
        self.finished = True
        return True


class UltrasoundJob:
    """A request's view of a ranging (two requests during one ranging share it)."""

    def __init__(self, ranging: _Ranging, convert: Callable[[int], Any]) -> None:
        self._ranging = ranging
        self._convert = convert
        self._cancelled = False

    def done(self) -> bool:
        return self._cancelled or self._ranging.step()

    def error(self) -> BaseException | None:
        if self._cancelled:
            return CancelledError("cancelled")
        return self._ranging.error if self._ranging.finished else None

    def result(self) -> Any:
        if not self._ranging.finished or self.error() is not None:
            return None
        assert self._ranging.distance_cm is not None
        return self._convert(self._ranging.distance_cm)

    def cancel(self) -> None:
        """Stop waiting (the chip finishes its ranging anyway)."""
        if not self.done():
            self._cancelled = True


class HardwareSensors:
    """On-request sensors: :class:`~engine.services.interfaces.Sensors`."""

    def __init__(
        self,
        *,
        temperature: TemperatureSensor | None = None,
        ultrasound: UltrasoundSensor | None = None,
    ) -> None:
        self.temperature = temperature
        self.ultrasound = ultrasound

    def read(self, sensor: str) -> Job:
        """Read ``temperature`` or ``ultrasound``; the result maps blackboard keys to values."""
        if sensor not in ON_REQUEST_SENSORS:
            known = ", ".join(ON_REQUEST_SENSORS)
            return ImmediateJob(error=ServiceError(f"no sensor {sensor!r} (known: {known})"))
        device = self.temperature if sensor == "temperature" else self.ultrasound
        if device is None:
            return ImmediateJob(error=ServiceError(f"the robot config has no {sensor} sensor"))
        return device.read()
