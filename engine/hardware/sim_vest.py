"""The simulated vest: every device of a robot config as a register-level model, moved by
the scenario's world.

:func:`build_sim_vest` makes, for a :class:`~engine.hardware.config.RobotConfig`:

- a :class:`~engine.sim.i2c_bus.SimI2CBus` per I2C bus with the config's chips
  soldered on at their addresses (VL53L0X chips on XSHUT lines wait in hardware standby
  at 0x29 until the start-up chain switches them on and moves them; a TCA9548A bridges
  one downstream bus per channel);
- a :class:`~engine.sim.spi_bus.SimSpiDev` per SPI node (an MCP3008);
- a :class:`~engine.sim.maestro_emulator.MaestroEmulator` on a pseudo-terminal for
  the Maestro, with each joint's pulse limits as the channel's Min/Max;

and listens to the :class:`~engine.scenario.world.World`: a touched pad is a finger on the
MPR121's electrode; a squeeze is newtons on an FSR 406, volts on the ADC input
(:func:`~engine.sim.fsr.fsr406_volts`); an obstacle is the distance each VL53L0X
looks at, by its ``side``; a gesture is a hand in front of the ZX sensor (a "wave" is a
swipe to the right); the room's temperature is the MCP9808's air; an object ahead is the
SRF02's echo. The drivers then read all of it at register level, exactly as on the robot.

Faults: :meth:`SimVest.unplug` and :meth:`SimVest.fault` (also the world events
``unplug`` ``{device, seconds}`` and ``fault`` ``{device, kind, seconds}``) make a device
stop answering (I2C: NACK; SPI: MISO pulled high), answer garbage, or hold the whole I2C
bus, for a while. An unplugged chip has no power: a gesture made meanwhile is not seen.

On a :class:`~engine.clock.VirtualClock` the chips and the drivers share a
:class:`~engine.hardware.branching_clock.BranchingClock` (:attr:`SimVest.clock`), so inline polls
take their time on the chips without holding up the robot.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from typing import Any

from engine.blackboard.board import Blackboard
from engine.clock import Clock, VirtualClock
from engine.drivers.gpio import OutputLine
from engine.hardware.branching_clock import BranchingClock
from engine.hardware.chips import ChipRegistry, default_chips
from engine.hardware.config import BusConfig, DeviceConfig, RobotConfig
from engine.scenario.world import EVENT_KEYS, World
from engine.sim.fsr import fsr406_volts
from engine.sim.gpio import SimOutputLine
from engine.sim.i2c_bus import SimI2CBus, SimI2CDevice
from engine.sim.maestro_emulator import MaestroEmulator
from engine.sim.mcp3008 import SimMCP3008
from engine.sim.spi_bus import Bit, SimSpiDev, SimSpiDevice
from engine.sim.tca9548a import SimTCA9548A

_log = logging.getLogger("vest.sim_vest")

I2C_FAULTS = ("nack", "unplugged", "garbage", "hold")
SPI_FAULTS = ("unplugged", "garbage")
WAVE_AS = "swipe_right"
"""What the ZX sensor sees of a wave: a hand passing across it."""
FSR_SUPPLY_V = 3.3
FSR_DIVIDER_OHM = 10_000.0


class SpiSocket(SimSpiDevice):
    """A chip's socket on an SPI node: unplugged, MISO is pulled high (reads all ones);
    with garbage, it floats (random bits)."""

    def __init__(self, chip: SimSpiDevice, clock: Clock) -> None:
        self.chip = chip
        self._clock = clock
        self._fault: tuple[str, float] | None = None

    def inject(self, kind: str, seconds: float) -> None:
        self._fault = (kind, self._clock.now() + seconds)

    @property
    def fault(self) -> str | None:
        """The fault still active now, if any."""
        if self._fault is None:
            return None
        kind, until_s = self._fault
        return kind if self._clock.now() < until_s else None

    def frame(self, mosi_bits: Sequence[int], *, mode: int, speed_hz: int) -> list[Bit]:
        if self._fault is not None:
            kind, until_s = self._fault
            if self._clock.now() < until_s:
                return [1 if kind == "unplugged" else None] * len(mosi_bits)
            self._fault = None
        return self.chip.frame(mosi_bits, mode=mode, speed_hz=speed_hz)


class SimVest:
    """The simulated chips of one robot config, behind simulated buses; a world listener.

    Also what :func:`~engine.hardware.assembly.build_hardware` opens instead of real buses
    (:meth:`open_i2c`, :meth:`open_spi`, :meth:`serial_port`, :meth:`output_line`).
    ``chips`` maps each device name to its model (``vest.chips["touch"]`` is a
    :class:`~engine.sim.mpr121.SimMPR121`).
    """

    def __init__(
        self,
        config: RobotConfig,
        world: World,
        clock: Clock,
        chip_kinds: ChipRegistry | None = None,
    ) -> None:
        self.config = config
        self.world = world
        self.chip_kinds = chip_kinds or default_chips()
        self.base_clock = clock
        self.clock: Clock = BranchingClock(clock) if isinstance(clock, VirtualClock) else clock
        self.i2c: dict[str, SimI2CBus] = {}
        self.spi: dict[str, SimSpiDev] = {}
        self.chips: dict[str, Any] = {}
        self.maestro: MaestroEmulator | None = None
        self._sockets: dict[str, SpiSocket] = {}
        self._places: dict[str, tuple[SimI2CBus, int]] = {}
        self._mux_buses: dict[tuple[str, int], SimI2CBus] = {}
        self._lines: dict[int, SimOutputLine] = {}
        self._closed = False
        for bus in config.buses.values():
            if bus.kind == "i2c":
                self.i2c[bus.name] = SimI2CBus(self.clock, bus_number=bus.number or 0)
        try:
            # Muxes first: the chips behind them go onto their downstream buses.
            for device in config.devices.values():
                if device.role == "mux":
                    self._add(device)
            for device in config.devices.values():
                if device.role != "mux":
                    self._add(device)
        except BaseException:
            self.close()
            raise

    # -- making the chips ------------------------------------------------------------------
    def _add(self, device: DeviceConfig) -> None:
        kind = self.chip_kinds.get(device.chip)
        if kind is None or kind.simulate is None:  # pragma: no cover - every kind has one
            raise ValueError(f"the simulated vest has no model of {device.chip!r}")
        kind.simulate(self, device)

    # -- what a chip kind's model is placed with (chips.kind.SimPlacement) -----------------
    def i2c_bus_for(self, device: DeviceConfig) -> SimI2CBus:
        return self._bus_for(device)

    def attach_i2c(self, device: DeviceConfig, model: SimI2CDevice) -> None:
        bus = self._bus_for(device)
        bus.attach(model)
        self.keep(device, model, bus)

    def keep(self, device: DeviceConfig, model: Any, bus: SimI2CBus | None = None) -> None:
        self.chips[device.name] = model
        if bus is not None and device.address is not None:
            self._places[device.name] = (bus, device.address)

    def add_mux(self, device: DeviceConfig) -> None:
        """A TCA9548A: eight downstream buses behind one address."""
        bus_config = self.config.buses[device.bus]
        bus = self._bus_for(device)
        assert device.address is not None
        downstream = [
            SimI2CBus(self.clock, bus_number=100 * (bus_config.number or 0) + channel)
            for channel in range(8)
        ]
        for channel, channel_bus in enumerate(downstream):
            self._mux_buses[(device.name, channel)] = channel_bus
        self.keep(device, SimTCA9548A(device.address, downstream, upstream=bus), bus)

    def add_spi(self, device: DeviceConfig) -> None:
        """An MCP3008 on its SPI node, its inputs moved by the world's forces."""
        bus_config = self.config.buses[device.bus]
        chip = SimMCP3008(vref_v=device.options.get("vref_v", 3.3))
        socket = SpiSocket(chip, self.clock)
        self.spi[bus_config.name] = SimSpiDev(socket, bus_config.number, bus_config.chip_select)
        self._sockets[device.name] = socket
        self.chips[device.name] = chip

    def add_maestro(self, device: DeviceConfig) -> None:
        self._add_maestro(device)

    def _bus_for(self, device: DeviceConfig) -> SimI2CBus:
        if device.mux is not None:
            assert device.mux_channel is not None
            return self._mux_buses[(device.mux, device.mux_channel)]
        return self.i2c[device.bus]

    def _add_maestro(self, device: DeviceConfig) -> None:
        limits = {joint.channel: (joint.min_us, joint.max_us) for joint in device.joints}
        self.maestro = MaestroEmulator(
            self.base_clock,
            channels=int(device.options.get("channels", 12)),
            device=int(device.options.get("device_number", 12)),
            limits_us=limits,
        )
        self.chips[device.name] = self.maestro

    # -- what build_hardware opens -----------------------------------------------------------
    def open_i2c(self, bus: BusConfig) -> SimI2CBus:
        return self.i2c[bus.name]

    def open_spi(self, bus: BusConfig) -> SimSpiDev:
        return self.spi[bus.name]

    def serial_port(self, bus: BusConfig) -> str:
        """The emulator's pseudo-terminal, opened by the Maestro driver as ``/dev/ttyACM0``."""
        if self.maestro is None:
            raise ValueError(f"no Maestro on simulated serial bus {bus.name!r}")
        return self.maestro.port_name

    def output_line(self, offset: int, consumer: str = "vest") -> OutputLine:
        """The GPIO line ``offset``: wired to the XSHUT pin of the VL53L0X that names it."""
        line = self._lines.get(offset)
        if line is None:
            target: Callable[[bool], None] = _unconnected
            for device in self.config.devices.values():
                if device.xshut == offset:
                    target = self.chips[device.name].set_xshut
            line = SimOutputLine(target)
            self._lines[offset] = line
        return line

    def close(self) -> None:
        """Stop the Maestro emulator (its pseudo-terminal disappears)."""
        if self._closed:
            return
        self._closed = True
        if self.maestro is not None:
            self.maestro.close()

    # -- faults ----------------------------------------------------------------------------
    def unplug(self, device: str, seconds: float) -> None:
        """``device`` stops answering for ``seconds`` (its chip keeps its registers)."""
        self.fault(device, "unplugged", seconds)

    def fault(self, device: str, kind: str, seconds: float) -> None:
        """``device`` misbehaves for ``seconds``: ``nack``, ``unplugged``, ``garbage`` (reads
        return random bytes) or, I2C only, ``hold`` (it holds SDA low: the whole bus times
        out)."""
        config = self.config.device(device)
        if not seconds > 0:
            raise ValueError(f"a fault lasts a positive number of seconds, got {seconds}")
        socket = self._sockets.get(device)
        if socket is not None:
            if kind not in SPI_FAULTS:
                raise ValueError(
                    f"{device!r} is on SPI: faults are {', '.join(SPI_FAULTS)}, not {kind!r}"
                )
            socket.inject(kind, seconds)
            return
        place = self._places.get(device)
        if place is None:
            raise ValueError(
                f"{device!r} ({config.chip}) cannot be unplugged in the simulation: "
                "the simulated vest fails I2C and SPI devices"
            )
        if kind not in I2C_FAULTS:
            raise ValueError(f"unknown fault {kind!r}: use {', '.join(I2C_FAULTS)}")
        bus, address = place
        bus.inject(kind, seconds, address)

    def unplugged(self, device: str) -> bool:
        """Whether ``device`` is unplugged now (an ``unplugged`` fault still active)."""
        socket = self._sockets.get(device)
        if socket is not None:
            return socket.fault == "unplugged"
        place = self._places.get(device)
        if place is None:
            return False
        bus, address = place
        return bus.fault_at(address) == "unplugged"

    # -- the world -------------------------------------------------------------------------
    def start(self) -> None:
        """Put the world's present state on the chips."""
        for what in ("touch", "force", "range", "temperature", "ultrasound"):
            self.world_changed(self.world, what)

    def world_changed(self, world: World, what: str) -> None:
        try:
            self._change(world, what)
        except ValueError as error:  # a world the chips cannot take must not stop the robot
            _log.error("simulated vest: cannot apply %s: %s", what, error)

    def _change(self, world: World, what: str) -> None:
        for device in self.config.devices.values():
            chip = self.chips.get(device.name)
            if chip is None:
                continue
            if what == "touch" and device.role == "touch":
                for pad, touching in enumerate(world.touched):
                    chip.touch(pad, touching)
            elif what == "force" and device.role == "force":
                for force_pad in device.pads:
                    force_n = world.force_n.get(force_pad.name)
                    if force_n is not None:
                        volts = fsr406_volts(
                            force_n, supply_v=FSR_SUPPLY_V, divider_ohm=FSR_DIVIDER_OHM
                        )
                        chip.set_input_volts(force_pad.channel, volts)
            elif what == "range" and device.role == "range" and device.side is not None:
                chip.distance_mm = world.range_mm.get(device.side)
            elif what == "temperature" and device.role == "temperature":
                chip.temperature_c = world.temperature_c
            elif what == "ultrasound" and device.role == "ultrasound":
                chip.distance_cm = world.ultrasound_cm

    def world_event(self, kind: str, value: Any) -> None:
        try:
            if kind == "gesture":
                for device in self.config.with_role("gesture"):
                    if self.unplugged(device.name):
                        continue  # a chip without power sees no hand
                    self.chips[device.name].perform(WAVE_AS if value == "wave" else value)
            elif kind in ("unplug", "fault") and value["device"] not in self.config.devices:
                return  # the camera: it hears the world itself
            elif kind == "unplug":
                self.unplug(value["device"], value["seconds"])
            elif kind == "fault":
                self.fault(value["device"], value["kind"], value["seconds"])
        except (ValueError, KeyError) as error:
            _log.error("simulated vest: cannot apply %s %r: %s", kind, value, error)


def _unconnected(high: bool) -> None:
    """A GPIO line wired to nothing."""


def build_sim_vest(config: RobotConfig, world: World, clock: Clock) -> SimVest:
    """The simulated vest of ``config``, listening to ``world`` and in its present state.

    Close it (:meth:`SimVest.close`) after the hardware built on it.
    """
    vest = SimVest(config, world, clock)
    world.add_listener(vest)
    vest.start()
    return vest


class UnwiredSenses:
    """World events no simulated device carries (speech heard, cloud commands), staged on the
    blackboard as the speech recognizer and the IoT client would. Use it beside a
    :class:`SimVest` instead of :class:`~engine.scenario.world.BlackboardSenses`, which
    would also write the polled senses straight onto the blackboard."""

    def __init__(self, blackboard: Blackboard, *, hear: bool = True) -> None:
        """``hear``: stage what people say as text (no speech recognition is running)."""
        self.blackboard = blackboard
        self.kinds = ("hear", "cloud") if hear else ("cloud",)

    def world_changed(self, world: World, what: str) -> None:
        """Everything that changes is sensed through the simulated chips."""

    def world_event(self, kind: str, value: Any) -> None:
        if kind == "hear" and kind in self.kinds:
            text = value.get("text") if isinstance(value, dict) else value
            if text is not None:  # a recording cannot be heard without a recognizer
                self.blackboard.stage_event(EVENT_KEYS[kind], text)
        elif kind in self.kinds:
            self.blackboard.stage_event(EVENT_KEYS[kind], value)
