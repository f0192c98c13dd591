"""Putting one robot's hardware together: buses, bus managers, drivers, pollers, services.

:func:`build_hardware` takes a checked :class:`~engine.hardware.config.RobotConfig` and
gives a :class:`Hardware`: a :class:`~engine.drivers.bus_manager.BusManager` per bus (and
per TCA9548A channel in use), every device claimed at its address with a probe that
re-checks its identity while it is offline, the VL53L0X chips moved to their addresses
through their XSHUT lines (an :class:`~engine.hardware.xshut.XshutChain` per bus, which
keeps the lines to bring a lost chip back), a :class:`~engine.hardware.pollers.Poller` per
polled device, and the services (LEDs, servos, on-request sensors) on their drivers.

A bus with a TCA9548A is one adapter for the chips on it and those behind every channel:
its bus manager and the channels' managers share one
:class:`~engine.drivers.tca9548a.LockedBus`, so no two of them reach the adapter at once
(smbus2 keeps the target address per open file). The channels' managers exist whether the
mux answers at start-up or not; a channel access selects its channel first, so a mux that
is late or gone fails those accesses as ordinary bus errors, re-probed until it answers.

Buses come from the simulated vest (``vest=``, see :mod:`engine.hardware.sim_vest`) or from
the machine: ``smbus2.SMBus(n)`` for ``/dev/i2c-n``, ``spidev.SpiDev`` for SPI nodes,
pyserial (through :class:`~engine.drivers.maestro.Maestro`) for the Maestro's port, the
GPIO character device for XSHUT lines. Those modules are imported only when a real bus
is opened.

Two ways to run, chosen by the clock unless ``threaded`` says otherwise:

- inline (a :class:`~engine.clock.VirtualClock`: ``vest run --fast``, tests): bus managers
  run each transaction in the caller's thread; the pollers, the LED timer and the re-probes
  are scheduler hooks (:attr:`Hardware.hooks`) and each poll's waits stay in its own
  :class:`~engine.hardware.branching_clock.BranchingClock` branch. Deterministic.
- threaded (a real clock; always on real buses): one worker per bus, one thread per
  poller (:meth:`Hardware.start`), the LED timer still a scheduler hook.

A device that does not answer at start-up does not stop the robot: it is listed in
:attr:`Hardware.startup_problems`, shown offline on the blackboard, and tried again by
its poller or at its next request.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from engine.blackboard.board import Blackboard
from engine.clock import Clock, VirtualClock
from engine.drivers.bus_errors import describe_exception
from engine.drivers.bus_manager import BusManager, DeviceHandle
from engine.drivers.maestro import Maestro
from engine.drivers.tca9548a import TCA9548A, LockedBus
from engine.errors import DeviceError
from engine.hardware.actuator_services import HardwareServos
from engine.hardware.branching_clock import BranchingClock
from engine.hardware.chips import ChipRegistry, default_chips
from engine.hardware.config import BusConfig, DeviceConfig, RobotConfig
from engine.hardware.device_health import DeviceHealth
from engine.hardware.pollers import Poller, make_poller
from engine.hardware.real_buses import BusProvider, RealBuses
from engine.hardware.robot_hardware import Hardware
from engine.hardware.xshut import XshutChain

_log = logging.getLogger("vest.hardware")

_OFFLINE_AFTER = 3  # the bus managers' default: failed transactions that mark a device offline


def probe_for(
    device: DeviceConfig, chips: ChipRegistry | None = None
) -> Callable[[Any], object] | None:
    """The chip kind's read of its identity at the device's address (None: nothing to read)."""
    kind = (chips or default_chips()).get(device.chip)
    if device.address is None or kind is None or kind.probe is None:
        return None
    return kind.probe(device.address)


def build_hardware(
    config: RobotConfig,
    clock: Clock,
    blackboard: Blackboard | None,
    *,
    vest: BusProvider | None = None,
    threaded: bool | None = None,
    home_servos: bool = True,
) -> Hardware:
    """The hardware of ``config``: on the simulated ``vest``, or on the machine's buses.

    ``clock`` is the robot's clock; with a vest from :func:`~engine.hardware.sim_vest.
    build_sim_vest`, the drivers use the vest's clock (the same time). ``threaded``
    defaults to False on a :class:`~engine.clock.VirtualClock`, True otherwise; a real
    clock needs threads. ``blackboard`` receives ``/devices/<name>/ok`` and the
    pollers' readings (None: nothing is staged, for ``vest devices``).

    Raises :class:`~engine.errors.DeviceError` when a bus cannot be opened; a device that
    does not answer is only listed in :attr:`Hardware.startup_problems`.
    """
    virtual = isinstance(clock, VirtualClock)
    if threaded is None:
        threaded = not virtual
    driver_clock: Clock = getattr(vest, "clock", None) or (
        BranchingClock(clock) if virtual and not threaded else clock
    )
    if isinstance(driver_clock, BranchingClock) and driver_clock.base is not clock:
        raise ValueError("the simulated vest was built on another clock than the robot's")
    if not threaded and not virtual:
        raise ValueError(
            "inline hardware needs a VirtualClock; on a real clock use threaded=True "
            "(the drivers' waits would stall the trees)"
        )
    provider: BusProvider = vest if vest is not None else RealBuses(config)
    hardware = Hardware(config=config, clock=driver_clock, threaded=threaded)
    if isinstance(provider, RealBuses):
        hardware._owned.append(provider)
    try:
        _Assembler(hardware, provider, blackboard).build(home_servos=home_servos)
    except BaseException:
        hardware.close()
        raise
    for name, why in hardware.startup_problems.items():
        _log.warning("%s did not start: %s", name, why)
    return hardware


class _Assembler:
    def __init__(
        self, hardware: Hardware, provider: BusProvider, blackboard: Blackboard | None
    ) -> None:
        self.hw = hardware
        self.config = hardware.config
        self.provider = provider
        self.blackboard = blackboard
        self.clock = hardware.clock
        self.chips = default_chips()
        self._upstream: dict[str, LockedBus] = {}

    def _manager(self, bus: Any, *, name: str, kind: str) -> BusManager[Any]:
        health = self.hw.health

        def on_status(device: str, ok: bool) -> None:
            status = health.get(device)
            if status is not None:
                status.bus_status(ok)

        return BusManager(
            bus,
            name=name,
            clock=self.clock,
            kind=kind,
            threaded=self.hw.threaded,
            on_status=on_status,
        )

    def build(self, *, home_servos: bool) -> None:
        config = self.config
        for device in config.devices.values():
            self.hw.health[device.name] = DeviceHealth(device.name, self.blackboard)
        used = {device.bus for device in config.devices.values()}
        muxed = {device.bus for device in config.devices.values() if device.role == "mux"}
        for bus in config.buses.values():
            if bus.name in used and bus.kind != "serial":
                opened = (
                    self.provider.open_i2c(bus)
                    if bus.kind == "i2c"
                    else self.provider.open_spi(bus)
                )
                if bus.name in muxed:
                    # One adapter for the upstream chips and every mux channel: each access
                    # holds one lock (smbus2 sets the target address per open file).
                    opened = LockedBus(opened)
                    self._upstream[bus.name] = opened
                name = str(bus.number) if bus.kind == "i2c" else bus.path
                self.hw.managers[bus.name] = self._manager(opened, name=name, kind=bus.kind.upper())
        for device in config.devices.values():
            if device.role == "mux":
                self._mux(device)
        for bus in config.buses.values():
            chain = [
                d
                for d in config.devices.values()
                if d.bus == bus.name and d.xshut is not None  # re-addressed by XSHUT
            ]
            if chain:
                self._xshut_chain(bus, chain)
        for device in config.devices.values():
            if device.role != "mux":
                self._device(device)
        if home_servos and self.hw.servos is not None:
            try:
                self.hw.servos.home()
            except Exception as error:
                self._failed(self.hw.servos.device, error)

    def _failed(self, device: DeviceConfig, error: BaseException) -> None:
        self.hw.startup_problems[device.name] = describe_exception(error)

    def _claim(self, device: DeviceConfig) -> DeviceHandle[Any]:
        if device.mux is not None:
            manager = self.hw.managers[f"{device.bus}:{device.mux}.{device.mux_channel}"]
        else:
            manager = self.hw.managers[device.bus]
        handle = manager.claim(device.name, device.address, probe=probe_for(device))
        self.hw.handles[device.name] = handle
        return handle

    def _mux(self, device: DeviceConfig) -> None:
        """The TCA9548A and a bus manager per channel in use, whether it answers now or not.

        Nothing is sent to build it: each channel access selects its channel, so a mux that
        is late or missing fails those accesses as ordinary bus errors, which the channel's
        bus manager retries and re-probes. Its health follows its answers.
        """
        assert device.address is not None
        health = self.hw.health[device.name]
        mux = TCA9548A(
            self._upstream[device.bus],
            address=device.address,
            check=False,
            on_answer=lambda ok, why: health.driver_status(ok, why),
        )
        self.hw.muxes[device.name] = mux
        manager = self.hw.managers[device.bus]

        def check(bus: Any) -> list[int]:
            return mux.selected()

        handle = manager.claim(device.name, device.address, probe=check)
        self.hw.handles[device.name] = handle
        channels = sorted(
            {
                d.mux_channel
                for d in self.config.devices.values()
                if d.mux == device.name and d.mux_channel is not None
            }
        )
        for channel in channels:
            self.hw.managers[f"{device.bus}:{device.name}.{channel}"] = self._manager(
                mux.channel_bus(channel),
                name=f"{self.config.buses[device.bus].number} via {device.name} ch{channel}",
                kind="I2C",
            )
        try:
            handle.call(check)
        except Exception as error:
            self._failed(device, error)
            self._until_offline(device, handle, check)

    def _xshut_chain(self, bus: BusConfig, members: list[DeviceConfig]) -> None:
        """Switch the VL53L0X chips on one at a time, each moved off 0x29 before the next;
        the chain keeps their lines to bring a chip back later."""
        lines = [
            (device, self.provider.output_line(device.xshut or 0, f"vest {device.name} XSHUT"))
            for device in members
        ]
        chain = XshutChain(self.hw.managers[bus.name], lines, self.clock)
        self.hw.chains[bus.name] = chain
        self.hw.startup_problems.update(chain.start())

    def _device(self, device: DeviceConfig) -> None:
        hw = self.hw
        if device.role == "servos":
            self._servos(device)
            return
        handle = self._claim(device)
        poller: Poller[Any] | None = None
        if device.polled:
            try:
                poller = make_poller(
                    device,
                    handle,
                    clock=self.clock,
                    blackboard=self.blackboard or _NO_BLACKBOARD,
                    health=hw.health[device.name],
                    chain=hw.chains.get(device.bus) if device.xshut is not None else None,
                )
            except Exception as error:  # nothing will ever read it: say so, for good
                self._failed(device, error)
                hw.health[device.name].driver_status(False, describe_exception(error))
                return
            hw.pollers.append(poller)
        try:
            if poller is not None:
                if device.name not in hw.startup_problems:
                    poller.connect()
            else:
                kind = self.chips.get(device.chip)
                if kind is not None and kind.service is not None:
                    service = kind.service(device, handle, self.clock)
                    hw.place(device.role, service)
                    service.connect()
        except Exception as error:
            if device.name not in hw.startup_problems:
                self._failed(device, error)
            if not device.polled:
                self._until_offline(device, handle)

    def _until_offline(
        self,
        device: DeviceConfig,
        handle: DeviceHandle[Any],
        probe: Callable[[Any], object] | None = None,
    ) -> None:
        """A device read on request that failed at start-up: probe it until the bus manager
        takes it offline (then it is re-probed by itself, and back when it answers)."""
        probe = probe or probe_for(device)
        if probe is None:
            return
        for _ in range(_OFFLINE_AFTER):
            try:
                handle.call(probe)
            except Exception:
                if not handle.online:
                    return
            else:
                return  # it answers after all; its driver is made at the first request

    def _servos(self, device: DeviceConfig) -> None:
        bus = self.config.buses[device.bus]
        port = self.provider.serial_port(bus)
        options = {
            "device": device.options["device_number"],
            "protocol": device.options["protocol"],
            "channels": device.options["channels"],
            "clock": self.clock,
            "baudrate": bus.baudrate,
        }
        try:
            maestro = Maestro(port, **options)
        except DeviceError as error:
            if not isinstance(port, str):
                raise
            # not plugged in yet: the robot starts without its servos, and the first move
            # after the Maestro appears opens the port (moves meanwhile fail in words)
            self._failed(device, error)
            self.hw.health[device.name].driver_status(False, describe_exception(error))
            maestro = Maestro(port, connect=False, **options)
        self.hw._owned.append(maestro)
        manager = self._manager(maestro, name=bus.path, kind="serial")
        self.hw.managers[bus.name] = manager
        handle = manager.claim(device.name, None)
        self.hw.handles[device.name] = handle
        self.hw.servos = HardwareServos(device, handle, self.clock)


class _NoBlackboard:
    """Where pollers stage when nobody listens (``vest devices``)."""

    def stage(self, key: str, value: Any) -> None:
        """Dropped."""

    def stage_event(self, key: str, value: Any) -> None:
        """Dropped."""


_NO_BLACKBOARD: Any = _NoBlackboard()
