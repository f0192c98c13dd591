"""One robot's hardware, built: its bus managers, device handles, health, pollers and
services (made by :func:`engine.hardware.assembly.build_hardware`)."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from engine.clock import Clock
from engine.drivers.bus_manager import BusManager, DeviceHandle, DeviceStats
from engine.drivers.tca9548a import TCA9548A
from engine.errors import ConfigError
from engine.hardware.actuator_services import HardwareLeds, HardwareServos
from engine.hardware.branching_clock import branch_of
from engine.hardware.config import RobotConfig
from engine.hardware.device_health import DeviceHealth
from engine.hardware.pollers import Poller, PollerThreads
from engine.hardware.sensor_services import HardwareSensors, TemperatureSensor, UltrasoundSensor
from engine.hardware.xshut import XshutChain
from engine.services.interfaces import IotResults, Services, Speech

_log = logging.getLogger("vest.hardware")

Hook = Callable[[float], None]


@dataclass
class Hardware:
    """One robot's buses, devices, pollers and services. Close it when done."""

    config: RobotConfig
    clock: Clock
    """The drivers' clock (a :class:`BranchingClock` when inline on a virtual clock)."""
    threaded: bool
    managers: dict[str, BusManager[Any]] = field(default_factory=dict)
    handles: dict[str, DeviceHandle[Any]] = field(default_factory=dict)
    health: dict[str, DeviceHealth] = field(default_factory=dict)
    pollers: list[Poller[Any]] = field(default_factory=list)
    leds: HardwareLeds | None = None
    servos: HardwareServos | None = None
    sensors: HardwareSensors = field(default_factory=HardwareSensors)
    startup_problems: dict[str, str] = field(default_factory=dict)
    """Devices that did not start, and why (they are retried while the robot runs)."""
    muxes: dict[str, TCA9548A] = field(default_factory=dict)
    chains: dict[str, XshutChain] = field(default_factory=dict)
    """The VL53L0X XSHUT chain of each bus that has one, by bus name."""
    _owned: list[Any] = field(default_factory=list)
    _threads: PollerThreads | None = None
    _closed: bool = False

    # -- running -------------------------------------------------------------------------
    @property
    def hooks(self) -> list[Hook]:
        """Scheduler hooks: inline, the pollers and re-probes; always the LED timer."""
        hooks: list[Hook] = []
        if not self.threaded:
            hooks.extend(self.pollers)
            hooks.append(self.run_due_probes)
        if self.leds is not None:
            hooks.append(self.leds)
        return hooks

    def run_due_probes(self, now_s: float) -> None:
        """Re-probe offline devices that are due (inline; workers do it themselves)."""
        for manager in self.managers.values():
            with branch_of(self.clock):
                manager.run_due_probes()

    def place(self, role: str, service: object) -> None:
        """Keep a device's service where the robot's services are found, by its role."""
        if role == "leds" and isinstance(service, HardwareLeds):
            self.leds = service
        elif role == "temperature" and isinstance(service, TemperatureSensor):
            self.sensors.temperature = service
        elif role == "ultrasound" and isinstance(service, UltrasoundSensor):
            self.sensors.ultrasound = service
        else:
            raise ValueError(f"no place for a {type(service).__name__} as {role!r}")

    def start(self, origin_s: float | None = None) -> None:
        """Threaded: start the poller threads (inline, the hooks poll).

        ``origin_s``: the trees' first deadline, so readings are staged just before ticks.
        """
        if self.threaded and self._threads is None:
            self._threads = PollerThreads(self.pollers, self.clock)
            self._threads.start(origin_s)

    def stop(self) -> None:
        """Stop the poller threads, if running."""
        if self._threads is not None:
            self._threads.stop()
            self._threads = None

    def services(
        self, *, speech: Speech, iot: IotResults, fallback: Services | None = None
    ) -> Services:
        """The robot's services: LEDs, servos and sensors from this hardware, ``speech`` and
        ``iot`` as given; what the config lacks comes from ``fallback``."""
        missing = [
            what for what, have in (("leds", self.leds), ("servos", self.servos)) if have is None
        ]
        if missing and fallback is None:
            raise ConfigError(
                f"{self.config.path}: no device for {', '.join(missing)}; add one or pass a "
                "fallback"
            )
        return Services(
            speech=speech,
            leds=self.leds if self.leds is not None else fallback.leds,  # type: ignore[union-attr]
            servos=self.servos if self.servos is not None else fallback.servos,  # type: ignore[union-attr]
            sensors=self.sensors,
            iot=iot,
        )

    def stats(self) -> dict[str, DeviceStats]:
        """Every device's bus statistics, by device name."""
        snapshot: dict[str, DeviceStats] = {}
        for manager in self.managers.values():
            snapshot.update(manager.stats())
        return snapshot

    def poller(self, name: str) -> Poller[Any]:
        for poller in self.pollers:
            if poller.name == name:
                return poller
        raise KeyError(f"no poller for device {name!r}")

    def close(self) -> None:
        """Stop pollers, let their chips rest (range sensors stop ranging), stop bus workers;
        close what was opened here (never the sim vest)."""
        if self._closed:
            return
        self._closed = True
        self.stop()
        for poller in self.pollers:  # while the bus workers still run
            poller.release()
        for manager in self.managers.values():
            manager.close()
        for thing in reversed(self._owned):
            try:
                thing.close()
            except OSError as error:
                _log.warning("closing %r: %s", thing, error)

    def __enter__(self) -> Hardware:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
