"""Temperature (MCP9808) and ultrasound (SRF02) read on request as services: a job at once,
the reading staged when it is done; see :mod:`engine.hardware.services`."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import CancelledError, Future
from typing import Any, TypeVar

from engine.clock import Clock
from engine.drivers.bus_manager import DeviceHandle
from engine.drivers.mcp9808 import MCP9808, celsius_to_fahrenheit
from engine.drivers.srf02 import MAX_POLLS, POLL_INTERVAL_S, SRF02
from engine.drivers.srf02_registers import RANGING_TIME_S
from engine.errors import ServiceError
from engine.hardware.config import DeviceConfig
from engine.hardware.services import FutureResultJob, OnDevice
from engine.services.interfaces import ON_REQUEST_SENSORS
from engine.services.jobs import ImmediateJob, Job

D = TypeVar("D")
T = TypeVar("T")


class TemperatureSensor:
    """The MCP9808: one register read per request."""

    def __init__(self, device: DeviceConfig, handle: DeviceHandle[Any], clock: Clock) -> None:
        self.device = device
        self.keys = device.keys
        self._on = OnDevice(device, handle, clock, self._make)

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
        self._on = OnDevice(device, handle, clock, self._make)
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

    def __init__(self, on: OnDevice[SRF02], clock: Clock) -> None:
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
