"""Robot configs: which devices the vest has, where they sit and which keys they feed.

::

    name: hbs2
    simulated: false              # true: the same devices as register-level models
    buses:
      i2c: {kind: i2c, number: 1}                     # /dev/i2c-1
      servos: {kind: serial, port: /dev/ttyACM0}
    gpio: {chip: /dev/gpiochip0}                      # XSHUT lines of the VL53L0X chain
    devices:
      touch: {chip: mpr121, bus: i2c, address: 0x5A, rate_hz: 20}
      force:
        chip: ads1115
        pads:
          left: {channel: 0, calibration: [[0.0, 0.0], [0.83, 0.2], [3.0, 6.0]]}
      range_left: {chip: vl53l0x, side: left, address: 0x30, xshut: 17}
      ...

Every device has a ``chip`` (one of :data:`CHIPS`), a ``bus`` (optional when the config
has one bus of the kind the chip needs), an ``address`` (I2C chips; default the chip's
power-on address), ``rate_hz`` (polled chips only) and ``keys`` (what each of its readings
feeds on the blackboard; sensible defaults). Chip options are the drivers' keyword options.

:func:`~engine.hardware.config_file.load_robot_config` checks the whole file (the rules are in
:mod:`engine.hardware.config_check`) and raises a :class:`~engine.files.problems.LoadError`
listing every problem with its file:line:column, as the tree loader does.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from engine.drivers.servo_joints import Joint
from engine.errors import ConfigError
from engine.files.problems import Mark
from engine.values.param_problems import did_you_mean
from engine.values.params import Param

BUS_KINDS = ("i2c", "spi", "serial")
SIDES = ("left", "center", "right")
ZX_GESTURES = (
    "swipe_right",
    "swipe_left",
    "swipe_up",
    "hover",
    "hover_left",
    "hover_right",
    "hover_up",
)
ENGINE_GESTURES = ("wave", *ZX_GESTURES)
"""The gesture names trees react to (the scenario's and the catalogue's vocabulary)."""

PCA9685_ALL_CALL = 0x70
VL53L0X_BOOT_ADDRESS = 0x29


def hex_address(address: int | None) -> str:
    """``0x5A`` (or ``no address``)."""
    return "no address" if address is None else f"0x{address:02X}"


# -- what each chip is --------------------------------------------------------------------------
@dataclass(frozen=True)
class ChipSpec:
    """What a chip is to the config: its bus, addresses, role, readings and options.

    ``role`` says what the engine does with it: a polled sense (touch, force, range,
    gesture), an on-request sensor (temperature, ultrasound), an actuator (leds, servos) or
    a bus part (mux). ``outputs`` maps each reading to its default blackboard key ("" when
    the default depends on another field). ``options`` are the driver's keyword options;
    ``fields`` the chip's structured fields, checked by their own code.
    """

    chip: str
    summary: str
    bus_kind: str
    role: str
    addresses: tuple[int, ...] = ()
    default_address: int | None = None
    default_rate_hz: float | None = None
    outputs: dict[str, str] = field(default_factory=dict)
    options: tuple[Param[Any], ...] = ()
    fields: tuple[str, ...] = ()
    address_notes: dict[int, str] = field(default_factory=dict)
    """Why an address the chip's range would suggest is not allowed (a hint's first words)."""

    @property
    def polled(self) -> bool:
        return self.default_rate_hz is not None

    @property
    def has_address(self) -> bool:
        return self.bus_kind == "i2c"

    def addresses_text(self) -> str:
        runs: list[tuple[int, int]] = []
        for address in self.addresses:
            if runs and address == runs[-1][1] + 1:
                runs[-1] = (runs[-1][0], address)
            else:
                runs.append((address, address))
        return ", ".join(
            hex_address(low) if low == high else f"{hex_address(low)}..{hex_address(high)}"
            for low, high in runs
        )


COMMON_FIELDS = ("chip", "bus", "address", "rate_hz", "keys", "description")


# -- the checked config -------------------------------------------------------------------------
@dataclass(frozen=True)
class BusConfig:
    """One bus: an I2C adapter (``number``: /dev/i2c-N), an SPI node (/dev/spidevN.C) or a
    serial port."""

    name: str
    kind: str
    mark: Mark
    number: int | None = None
    chip_select: int | None = None
    port: str | None = None
    baudrate: int = 115200

    @property
    def path(self) -> str:
        """The device file: ``/dev/i2c-1``, ``/dev/spidev0.0``, ``/dev/ttyACM0``."""
        if self.kind == "i2c":
            return f"/dev/i2c-{self.number}"
        if self.kind == "spi":
            return f"/dev/spidev{self.number}.{self.chip_select}"
        return str(self.port)

    def describe(self) -> str:
        return f"{self.kind.upper() if self.kind != 'serial' else 'serial'} bus {self.name!r}"


@dataclass(frozen=True)
class ForcePad:
    """A force pad on an ADC channel, with its volts -> newtons table."""

    name: str
    channel: int
    key: str
    calibration: tuple[tuple[float, float], ...]
    mark: Mark


@dataclass(frozen=True)
class DeviceConfig:
    """One configured device. ``options`` are the driver's keyword options, converted."""

    name: str
    spec: ChipSpec
    bus: str
    mark: Mark
    address: int | None = None
    rate_hz: float | None = None
    keys: dict[str, str] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)
    pads: tuple[ForcePad, ...] = ()
    joints: tuple[Joint, ...] = ()
    leds: dict[str, tuple[int, int, int]] = field(default_factory=dict)
    side: str | None = None
    xshut: int | None = None
    mux: str | None = None
    mux_channel: int | None = None
    gesture_names: dict[str, str] = field(default_factory=dict)
    pad_names: tuple[str, ...] = ()
    """Touch pads' names, electrode 0 first (the config's ``pad_names``)."""
    squeeze_n: float | None = None
    """Force pads: a squeeze event when a pad's force rises past this (N)."""
    description: str = ""

    @property
    def chip(self) -> str:
        """The chip's config name (``mpr121``)."""
        return self.spec.chip

    @property
    def role(self) -> str:
        return self.spec.role

    @property
    def polled(self) -> bool:
        return self.spec.polled

    @property
    def fed_keys(self) -> list[str]:
        """Every blackboard key this device feeds."""
        return [*self.keys.values(), *(pad.key for pad in self.pads)]

    def where(self, bus: BusConfig) -> str:
        """``I2C 0x5A on /dev/i2c-1`` (behind a mux: ``... via mux channel 2``)."""
        if self.address is None:
            return f"{bus.kind if bus.kind == 'serial' else bus.kind.upper()} {bus.path}"
        text = f"I2C {hex_address(self.address)} on {bus.path}"
        if self.mux is not None:
            text += f" via {self.mux} channel {self.mux_channel}"
        return text


@dataclass(frozen=True)
class AudioConfig:
    """The ALSA devices for speech: names such as ``default`` or ``plughw:1,0``; None for
    none (the simulated vest's room carries the sound)."""

    microphone: str | None = "default"
    speaker: str | None = "default"

    @classmethod
    def for_simulation(cls) -> AudioConfig:
        return cls(microphone=None, speaker=None)


SIMULATED_CAMERA = "simulated"
CAMERA_NAME = "camera"
"""The camera's device name: ``/devices/camera/ok``, ``unplug: {device: camera}``."""


@dataclass(frozen=True)
class CameraConfig:
    """A checked ``camera:`` section. ``device``: an index, a path, or ``simulated``;
    ``crop``: the window's top-left (x, y) in px, or None to centre it; ``model``: a file,
    or None for the project's; ``providers``: None for the automatic choice."""

    device: int | str = SIMULATED_CAMERA
    width: int = 640
    height: int = 360
    fps: float = 15.0
    crop: tuple[int, int] | None = None
    model: Path | None = None
    threads: int = 1
    providers: tuple[str, ...] | None = None
    min_confidence: float = 0.6
    steady_frames: int = 3

    @property
    def simulated(self) -> bool:
        return self.device == SIMULATED_CAMERA


@dataclass(frozen=True)
class SafetyConfig:
    """The safety envelope (``safety:``): limits no tree, remote command or button can
    lift. Distances in mm (to the chest's range sensors), forces in N (the side pads),
    speeds in deg/s, volume and brightness as fractions 0..1. None: that rule is off.

    ``arms`` are the joints the distance and force rules cover; ``joint_limits`` narrow a
    joint's angles (deg) below what its servo allows. ``when_unsure`` is what an arm move
    does when a sensor a rule reads cannot be trusted (offline, stale, implausible):
    ``refuse`` (the default) or ``slow`` (at ``slow_speed_dps``).
    """

    arms: tuple[str, ...] = ()
    when_unsure: str = "refuse"
    still_within_mm: float | None = None
    slow_within_mm: float | None = None
    slow_speed_dps: float = 20.0
    stop_above_n: float | None = None
    max_volume: float = 1.0
    max_brightness: float = 1.0
    joint_limits: dict[str, tuple[float, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class RobotConfig:
    """A checked robot config."""

    name: str
    path: Path
    simulated: bool
    buses: dict[str, BusConfig]
    devices: dict[str, DeviceConfig]
    gpio_chip: str = "/dev/gpiochip0"
    description: str = ""
    audio: AudioConfig = field(default_factory=AudioConfig)
    camera: CameraConfig | None = None
    safety: SafetyConfig = field(default_factory=SafetyConfig)

    @property
    def senses_people(self) -> bool:
        """Whether anything of a real person can reach the robot: real chips, a
        microphone, a real camera (a simulated vest in its simulated room senses only
        what a scenario scripts)."""
        camera = self.camera is not None and not self.camera.simulated
        return not self.simulated or self.audio.microphone is not None or camera

    def device(self, name: str) -> DeviceConfig:
        """The device called ``name``; ConfigError naming the nearest and the known ones."""
        try:
            return self.devices[name]
        except KeyError:
            hint = did_you_mean(name, list(self.devices))
            known = ", ".join(self.devices) or "none"
            raise ConfigError(
                f"no device {name!r} in {self.path}"
                + (f" ({hint})" if hint else "")
                + f"; devices: {known}"
            ) from None

    def with_role(self, role: str) -> list[DeviceConfig]:
        """The devices doing ``role`` (touch, force, range, ..., leds, servos), in file order."""
        return [device for device in self.devices.values() if device.role == role]

    def bus_of(self, device: DeviceConfig) -> BusConfig:
        return self.buses[device.bus]

    def __iter__(self) -> Iterator[DeviceConfig]:
        return iter(self.devices.values())
