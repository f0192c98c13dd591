"""The face LEDs (PCA9685) and the servo joints (Maestro) as services: every call returns a
Job at once; see :mod:`engine.hardware.services`."""

from __future__ import annotations

from concurrent.futures import Future
from typing import Any, TypeVar

from engine.clock import Clock
from engine.colors import parse_color
from engine.drivers.bus_manager import DeviceHandle
from engine.drivers.pca9685 import PCA9685
from engine.drivers.rgb_leds import ALL, RgbLeds
from engine.drivers.servo_joints import Joint, ServoJoints
from engine.errors import ServiceError
from engine.hardware.config import DeviceConfig
from engine.hardware.services import OnDevice, TimedFutureJob
from engine.services.jobs import ImmediateJob, Job

D = TypeVar("D")
T = TypeVar("T")
LED_OFF_RETRY_S = 0.5


class HardwareLeds:
    """The face LEDs on the config's PCA9685: :class:`~engine.services.interfaces.Leds`.

    Also a scheduler hook: ``leds(now_s)`` turns the LEDs off when a ``seconds`` ran out,
    and tries again every :data:`LED_OFF_RETRY_S` until the chip took it.
    """

    def __init__(self, device: DeviceConfig, handle: DeviceHandle[Any], clock: Clock) -> None:
        self.device = device
        self.clock = clock
        self._on = OnDevice(device, handle, clock, self._make)
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
        self._on = OnDevice(
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

    def stop(self, joint: str) -> None:
        """Hold ``joint`` where the Maestro has it now (its target set to its position)."""
        if joint not in self.joints:
            return

        def hold(joints: ServoJoints) -> None:
            joints.move(joint, joints.position_deg(joint), self.joints[joint].max_speed_dps)

        self._on.submit(hold)
        self.angles_deg.pop(joint, None)  # where it stopped is known to the Maestro

    def rest_pose(self, joint: str) -> tuple[float, float | None]:
        """The joint's ``home_deg`` and its safe speed (``rest_speed_dps``)."""
        limits = self.joints.get(joint)
        if limits is None:
            return 0.0, None
        return limits.home_deg, limits.safe_speed_dps

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
