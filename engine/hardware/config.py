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
from engine.values.params import (
    Boolean,
    Choice,
    Integer,
    Number,
    Param,
    did_you_mean,
)

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


CHIPS: dict[str, ChipSpec] = {
    spec.chip: spec
    for spec in (
        ChipSpec(
            "mpr121",
            "NXP MPR121 capacitive touch, 12 pads",
            "i2c",
            "touch",
            addresses=tuple(range(0x5A, 0x5E)),
            default_address=0x5A,
            default_rate_hz=20.0,
            outputs={"pads": "/sensors/touch/pads", "any": "/sensors/touch/any"},
            options=(
                Param("touch_threshold", Integer(1, 255), 12, "touch threshold, counts"),
                Param("release_threshold", Integer(0, 255), 6, "release threshold, counts"),
            ),
        ),
        ChipSpec(
            "ads1115",
            "TI ADS1115 16-bit ADC with FSR 406 force pads",
            "i2c",
            "force",
            addresses=tuple(range(0x48, 0x4C)),
            default_address=0x48,
            default_rate_hz=20.0,
            options=(
                Param("gain", Choice(("2/3", "1", "2", "4", "8", "16")), "1", "PGA gain"),
                Param(
                    "data_rate_sps",
                    Choice(("8", "16", "32", "64", "128", "250", "475", "860")),
                    "860",
                    "conversions per second (a reading takes about its inverse)",
                ),
            ),
            fields=("pads",),
        ),
        ChipSpec(
            "mcp3008",
            "Microchip MCP3008 10-bit SPI ADC with FSR 406 force pads",
            "spi",
            "force",
            default_rate_hz=20.0,
            options=(
                Param("vref_v", Number(0.25, 5.5, "V"), 3.3, "reference voltage"),
                Param("max_speed_hz", Integer(10_000, 3_600_000), 1_000_000, "SPI clock"),
            ),
            fields=("pads",),
        ),
        ChipSpec(
            "vl53l0x",
            "ST VL53L0X time-of-flight distance",
            "i2c",
            "range",
            addresses=tuple(range(0x08, 0x78)),
            default_address=VL53L0X_BOOT_ADDRESS,
            default_rate_hz=10.0,
            outputs={"range": ""},
            options=(
                Param(
                    "timeout_s",
                    Number(0.05, 1.0, "s"),
                    0.1,
                    "longest measurement (one takes about 33 ms)",
                ),
            ),
            fields=("side", "xshut", "mux", "channel"),
        ),
        ChipSpec(
            "zx_gesture",
            "XYZ Interactive ZX gesture sensor",
            "i2c",
            "gesture",
            addresses=(0x10, 0x11),
            default_address=0x10,
            default_rate_hz=20.0,
            outputs={"gesture": "/sensors/gesture/last"},
            fields=("gesture_names",),
        ),
        ChipSpec(
            "srf02",
            "Devantech SRF02 ultrasonic range, read on request",
            "i2c",
            "ultrasound",
            addresses=tuple(range(0x70, 0x78)),  # 0x78..0x7F are reserved on I2C
            default_address=0x70,
            outputs={"range": "/sensors/ultrasound/cm"},
        ),
        ChipSpec(
            "mcp9808",
            "Microchip MCP9808 temperature, read on request",
            "i2c",
            "temperature",
            addresses=tuple(range(0x18, 0x20)),
            default_address=0x18,
            outputs={"celsius": "/sensors/temperature/c", "fahrenheit": "/sensors/temperature/f"},
            options=(
                Param(
                    "resolution_c",
                    Choice(("0.5", "0.25", "0.125", "0.0625")),
                    "0.0625",
                    "temperature step, degC",
                ),
            ),
        ),
        ChipSpec(
            "pca9685",
            "NXP PCA9685 16-channel PWM for the face LEDs",
            "i2c",
            "leds",
            addresses=tuple(a for a in range(0x40, 0x78) if a != PCA9685_ALL_CALL),
            default_address=0x40,
            options=(
                Param("frequency_hz", Number(24.0, 1526.0, "Hz"), 1000.0, "PWM frequency"),
                Param("common_anode", Boolean(), False, "LEDs lit while the output is low"),
            ),
            fields=("leds",),
        ),
        ChipSpec(
            "maestro",
            "Pololu Mini Maestro servo controller (USB serial)",
            "serial",
            "servos",
            options=(
                Param("channels", Choice(("6", "12", "18", "24")), "12", "servo channels"),
                Param("device_number", Integer(0, 127), 12, "Pololu-protocol device number"),
                Param("protocol", Choice(("compact", "pololu")), "compact", "serial protocol"),
            ),
            fields=("joints",),
        ),
        ChipSpec(
            "tca9548a",
            "TI TCA9548A 8-channel I2C multiplexer",
            "i2c",
            "mux",
            addresses=tuple(range(0x70, 0x78)),
            default_address=0x70,
        ),
    )
}
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
    chip: str
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
    description: str = ""

    @property
    def spec(self) -> ChipSpec:
        return CHIPS[self.chip]

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
class RobotConfig:
    """A checked robot config."""

    name: str
    path: Path
    simulated: bool
    buses: dict[str, BusConfig]
    devices: dict[str, DeviceConfig]
    gpio_chip: str = "/dev/gpiochip0"
    description: str = ""

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
