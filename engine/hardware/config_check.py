"""Checking a robot config: every rule, each problem with its file:line:column.

:func:`engine.hardware.config_file.load_robot_config` runs :class:`ConfigChecker` on a parsed
file: the buses, each device (its chip, bus, address, rate, keys, the driver's options and
the chip's own fields: force pads and their calibration tables, range sensors' side and
XSHUT line or mux channel, gesture names, LED channels, servo joints), then the rules
between devices (one device per address of one bus, the PCA9685's All Call address, the
VL53L0X chain, muxes, one feeder per blackboard key, one device per service). Every problem
is collected before the LoadError is raised, so a person fixes them all in one go.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from engine.blackboard.catalogue import KeyCatalogue
from engine.files.fields import converted, declared_fields
from engine.files.problems import Mark, Problems
from engine.files.yaml_source import YMap, YScalar, YValue, describe, plain
from engine.hardware.chips import ChipRegistry, default_chips
from engine.hardware.chips.fields import ChipFields, number_text
from engine.hardware.config import (
    CAMERA_NAME,
    COMMON_FIELDS,
    BusConfig,
    ChipSpec,
    DeviceConfig,
    RobotConfig,
    hex_address,
)
from engine.hardware.config_audio import check_audio
from engine.hardware.config_buses import check_buses
from engine.hardware.config_camera import check_camera
from engine.hardware.config_cross_checks import CrossChecks
from engine.hardware.config_keys import check_device_keys
from engine.hardware.config_safety import check_safety
from engine.values.param_problems import CheckContext, did_you_mean
from engine.values.params import RATE_HZ, Boolean, Integer, Param, ParamType, Text

TOP_FIELDS: tuple[str, ...] = ("name", "description", "simulated", "buses", "gpio", "audio")
TOP_FIELDS += ("camera", "devices", "safety")
DEVICE_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
"""A device name: it names ``/devices/<name>/ok`` and is written in trees, so an identifier."""
# Options whose YAML value is a number but which the drivers take from a fixed set.
_NUMERIC_CHOICES = {"gain", "data_rate_sps", "resolution_c", "channels"}


class ConfigChecker:
    """Checks one parsed config file named ``name``; :meth:`check` raises every problem."""

    def __init__(
        self,
        name: str,
        path: Path,
        catalogue: KeyCatalogue,
        chips: ChipRegistry | None = None,
    ) -> None:
        self.chips = chips or default_chips()
        self.name = name
        self.path = path
        self.ctx = CheckContext(catalogue)
        self.problems = Problems()
        self.start = Mark(name, 1, 1)

    # -- small helpers ---------------------------------------------------------------------
    def convert(self, kind: ParamType[Any], raw: YValue, what: str) -> Any:
        """``kind.convert`` of a value, or None after adding the problem at its place."""
        return converted(kind, raw, what, self.ctx, self.problems)

    def unknown_fields(self, raw: YMap, known: Sequence[str], what: str) -> None:
        self.problems.unknown_fields(raw.key_marks, known, what)

    def fields(self, raw: YMap, params: tuple[Param[Any], ...], what: str) -> dict[str, Any] | None:
        """Convert the declared ``params`` of ``raw`` (unknown fields are checked apart)."""
        return declared_fields(raw, params, what, self.ctx, self.problems)

    def mapping(self, raw: YValue | None, what: str, example: str) -> YMap | None:
        if raw is None:
            return None
        if not isinstance(raw, YMap):
            self.problems.add(raw.mark, f"{what} must be a mapping, got {describe(raw)}", example)
            return None
        return raw

    # -- the document ----------------------------------------------------------------------
    def check(self, document: YValue | None) -> RobotConfig:
        if not isinstance(document, YMap):
            self.problems.add(
                document.mark if document is not None else self.start,
                "a robot config is a mapping with 'buses:' and 'devices:'",
                "see examples/robots/sim.yaml",
            )
            self.problems.raise_if_any()
        assert isinstance(document, YMap)
        self.unknown_fields(document, TOP_FIELDS, "robot config")
        robot_name = self._text(document, "name", Path(self.name).stem)
        description = self._text(document, "description", "")
        simulated = False
        if "simulated" in document:
            simulated = bool(self.convert(Boolean(), document.entries["simulated"], "simulated"))
        gpio_chip = "/dev/gpiochip0"
        gpio = self.mapping(document.get("gpio"), "'gpio'", "e.g. gpio: {chip: /dev/gpiochip0}")
        if gpio is not None:
            self.unknown_fields(gpio, ("chip",), "gpio")
            if "chip" in gpio:
                gpio_chip = self.convert(Text(), gpio.entries["chip"], "chip") or gpio_chip
        audio = check_audio(self, document, simulated)
        camera = check_camera(self, document, simulated, self.path.parent)
        buses = check_buses(self, document)
        devices = self._devices(document, buses)
        if camera is not None and CAMERA_NAME in devices:
            self.problems.add(
                devices[CAMERA_NAME].mark,
                f"a device may not be called {CAMERA_NAME!r}: the camera section has the name",
                "rename the device, or say camera: none",
            )
        safety = check_safety(self, document, devices)
        self.problems.raise_if_any()
        assert safety is not None
        return RobotConfig(
            name=robot_name,
            path=self.path,
            simulated=simulated,
            buses=buses,
            devices=devices,
            gpio_chip=gpio_chip,
            description=description,
            audio=audio,
            camera=camera,
            safety=safety,
        )

    def _text(self, document: YMap, key: str, default: str) -> str:
        raw = document.get(key)
        if raw is None:
            return default
        value = self.convert(Text(), raw, key)
        return value if value is not None else default

    # -- buses ---------------------------------------------------------------------------
    # -- devices ---------------------------------------------------------------------------
    def _devices(self, document: YMap, buses: dict[str, BusConfig]) -> dict[str, DeviceConfig]:
        raw = document.get("devices")
        if raw is None:
            self.problems.add(
                document.mark, "a robot config needs 'devices:'", "e.g. touch: {chip: mpr121}"
            )
            return {}
        section = self.mapping(raw, "'devices'", "e.g. touch: {chip: mpr121}")
        devices: dict[str, DeviceConfig] = {}
        marks: dict[str, YMap] = {}
        if section is None:
            return devices
        for name, body in section.items():
            if not DEVICE_NAME.fullmatch(name):
                self.problems.add(
                    section.key_marks[name],
                    f"device name {name!r} is not an identifier: use letters, digits and _, "
                    "starting with a letter or _",
                    f"it names /devices/<name>/ok on the blackboard, e.g. {_identifier(name)!r}",
                )
                continue
            if isinstance(body, YMap):  # problems about a device as a whole point at its name
                body = YMap(body.entries, section.key_marks[name], body.key_marks)
            device = self._device(name, body, buses)
            if device is not None:
                devices[name] = device
                assert isinstance(body, YMap)
                marks[name] = body
        CrossChecks(self.problems, self.chips, buses, devices, marks).run()
        return devices

    def _device(self, name: str, body: YValue, buses: dict[str, BusConfig]) -> DeviceConfig | None:
        raw = self.mapping(body, f"device {name!r}", "e.g. {chip: mpr121, address: 0x5A}")
        if raw is None:
            return None
        chip_raw = raw.get("chip")
        if chip_raw is None:
            self.problems.add(
                raw.mark, f"device {name!r} needs 'chip'", "chips: " + ", ".join(self.chips.names)
            )
            return None
        chip = plain(chip_raw)
        kind = self.chips.get(chip) if isinstance(chip, str) else None
        if kind is None:
            self.problems.add(
                chip_raw.mark,
                f"unknown chip {chip!r}",
                (did_you_mean(chip, self.chips.names) if isinstance(chip, str) else None)
                or "chips: " + ", ".join(self.chips.names),
            )
            return None
        spec = kind.spec
        known = [*COMMON_FIELDS, *(p.name for p in spec.options), *spec.fields]
        self.unknown_fields(raw, known, spec.chip)
        bus = self._device_bus(name, raw, spec, buses)
        address = self._address(raw, spec)
        rate_hz = self._rate(raw, spec)
        options = self._options(raw, spec)
        extra = kind.check_fields(ChipFields(self, name, raw, spec, options))
        keys = check_device_keys(self, raw, spec, (extra or {}).get("side"))
        if bus is None or options is None or extra is None or keys is None:
            return None
        if spec.has_address and address is None:
            return None
        description = self._text(raw, "description", "")
        return DeviceConfig(
            name=name,
            spec=spec,
            bus=bus,
            mark=raw.mark,
            address=address,
            rate_hz=rate_hz,
            keys=keys,
            options=options,
            description=description,
            **extra,
        )

    def _device_bus(
        self, name: str, raw: YMap, spec: ChipSpec, buses: dict[str, BusConfig]
    ) -> str | None:
        wanted = spec.bus_kind
        raw_bus = raw.get("bus")
        if raw_bus is None:
            fitting = [bus.name for bus in buses.values() if bus.kind == wanted]
            if len(fitting) == 1:
                return fitting[0]
            self.problems.add(
                raw.mark,
                f"device {name!r} needs 'bus:' ({len(fitting)} {wanted} buses are configured)",
                "name one of: " + ", ".join(fitting) if fitting else f"add a {wanted} bus",
            )
            return None
        bus_name: str | None = self.convert(Text(), raw_bus, "bus")
        if bus_name is None:
            return None
        bus = buses.get(bus_name)
        if bus is None:
            self.problems.add(
                raw_bus.mark,
                f"unknown bus {bus_name!r}",
                did_you_mean(bus_name, list(buses)) or "buses: " + (", ".join(buses) or "none"),
            )
            return None
        if bus.kind != wanted:
            self.problems.add(
                raw_bus.mark,
                f"{spec.chip} is on {wanted.upper() if wanted != 'serial' else 'a serial port'}, "
                f"but bus {bus_name!r} is {bus.kind}",
                "name a bus of kind " + wanted,
            )
            return None
        return bus_name

    def _address(self, raw: YMap, spec: ChipSpec) -> int | None:
        value = raw.get("address")
        if not spec.has_address:
            if value is not None:
                self.problems.add(
                    raw.key_marks["address"],
                    f"{spec.chip} has no I2C address ({spec.bus_kind})",
                    "remove 'address'",
                )
            return None
        if value is None:
            return spec.default_address
        address: int | None = self.convert(Integer(0, 0x7F), value, "address")
        if address is None:
            return None
        if address not in spec.addresses:
            hint = f"use {spec.addresses_text()}"
            if address in spec.address_notes:
                hint = f"{spec.address_notes[address]}; {hint}"
            self.problems.add(
                value.mark,
                f"{spec.chip} cannot be at address {hex_address(address)}",
                hint,
            )
            return None
        return address

    def _rate(self, raw: YMap, spec: ChipSpec) -> float | None:
        value = raw.get("rate_hz")
        if not spec.polled:
            if value is not None:
                self.problems.add(
                    raw.key_marks["rate_hz"],
                    f"{spec.chip} is not polled ({spec.role} is read on request or commanded)",
                    "remove 'rate_hz'",
                )
            return None
        if value is None:
            return spec.default_rate_hz
        rate_hz: float | None = self.convert(RATE_HZ, value, "rate_hz")
        return rate_hz

    def _options(self, raw: YMap, spec: ChipSpec) -> dict[str, Any] | None:
        values: dict[str, Any] = {}
        ok = True
        for param in spec.options:
            value = raw.get(param.name)
            if value is None:
                converted = param.default
            elif param.name in _NUMERIC_CHOICES:
                # YAML reads 0.0625 and 12 as numbers; the choices are spelled as text.
                text = number_text(plain(value))
                converted = self.convert(param.type, YScalar(text, value.mark), param.name)
            else:
                converted = self.convert(param.type, value, param.name)
            if converted is None:
                ok = False
                continue
            values[param.name] = _numeric_choice(param.name, converted)
        return values if ok else None


def _identifier(name: str) -> str:
    """``name`` made an identifier (for a hint): other characters become ``_``."""
    text = re.sub(r"[^A-Za-z0-9_]", "_", name) or "device"
    return text if not text[0].isdigit() else "_" + text


def _numeric_choice(name: str, value: Any) -> Any:
    if name not in _NUMERIC_CHOICES:
        return value
    if value == "2/3":
        return 2 / 3
    number = float(value)
    return int(number) if number.is_integer() and name != "resolution_c" else number
