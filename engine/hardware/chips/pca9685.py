"""The NXP PCA9685 16-channel PWM driving the face's RGB LEDs."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.drivers import pca9685_registers as registers
from engine.hardware.actuator_services import HardwareLeds
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.kind import ChipKind, DevicesTogether, SimPlacement
from engine.hardware.config import PCA9685_ALL_CALL, ChipSpec, DeviceConfig
from engine.sim.pca9685 import SimPCA9685
from engine.values.params import REQUIRED, Boolean, Integer, Number, Param

LED_FIELDS = ("red", "green", "blue")


def _leds_check(fields: ChipFields) -> dict[str, tuple[int, int, int]] | None:
    section = fields.checker.mapping(
        fields.raw.get("leds"), "'leds'", "e.g. leds: {face: {red: 0, green: 1, blue: 2}}"
    )
    if section is None:
        if "leds" not in fields.raw:
            fields.checker.problems.add(
                fields.raw.mark,
                f"pca9685 device {fields.name!r} needs 'leds'",
                "e.g. leds: {face: {red: 0, green: 1, blue: 2}}",
            )
        return None
    leds: dict[str, tuple[int, int, int]] = {}
    owner: dict[int, str] = {}
    ok = True
    for led, body in section.items():
        if led == "all":
            fields.checker.problems.add(
                section.key_marks[led], "'all' names every LED", "choose another LED name"
            )
            ok = False
            continue
        raw = fields.checker.mapping(body, f"LED {led!r}", "e.g. {red: 0, green: 1, blue: 2}")
        if raw is None:
            ok = False
            continue
        fields.checker.unknown_fields(raw, LED_FIELDS, "LED")
        values = fields.checker.fields(
            raw,
            tuple(
                Param(color, Integer(0, 15), REQUIRED, "PCA9685 channel") for color in LED_FIELDS
            ),
            f"LED {led!r}",
        )
        if values is None:
            ok = False
            continue
        for color in LED_FIELDS:
            channel = values[color]
            if channel in owner:
                fields.checker.problems.add(
                    raw.entries[color].mark,
                    f"PCA9685 channel {channel} is already used by LED {owner[channel]!r}",
                    "give each color its own channel",
                )
                ok = False
            owner[channel] = f"{led}.{color}"
        leds[led] = (values["red"], values["green"], values["blue"])
    if not leds and ok:
        fields.checker.problems.add(section.mark, "'leds' lists no LED")
        ok = False
    return leds if ok else None


def _leds(fields: ChipFields) -> dict[str, Any] | None:
    leds = _leds_check(fields)
    return None if leds is None else {"leds": leds}


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    vest.attach_i2c(device, SimPCA9685(vest.clock, device.address))


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: bus.read_byte_data(address, registers.PRE_SCALE)


def _all_call(checks: DevicesTogether, mine: list[DeviceConfig]) -> None:
    """Until the PCA9685 driver turns All Call off, the chip also takes writes to 0x70."""
    for pwm in mine:
        for device in checks.devices.values():
            if (
                device is pwm
                or device.bus != pwm.bus
                or device.address != PCA9685_ALL_CALL
                or device.mux is not None
            ):
                continue
            hint = "move it to 0x71..0x77"
            if device.chip == "srf02":
                hint = (
                    "change the SRF02's address to 0x71..0x77 (0xE2..0xEE in Devantech's "
                    "8-bit numbering), e.g. 0x75"
                )
            checks.problems.add(
                checks.mark(device, "address"),
                f"{device.name!r} at 0x70 shares its bus with PCA9685 {pwm.name!r}, whose "
                "LED All Call address is 0x70: at power-up the PCA9685 also takes every "
                "write to 0x70 into its own registers",
                hint,
            )


KIND = ChipKind(
    ChipSpec(
        "pca9685",
        "NXP PCA9685 16-channel PWM for the face LEDs",
        "i2c",
        "leds",
        addresses=tuple(a for a in range(0x40, 0x78) if a != PCA9685_ALL_CALL),
        default_address=0x40,
        address_notes={PCA9685_ALL_CALL: "0x70 is every PCA9685's LED All Call address"},
        options=(
            Param("frequency_hz", Number(24.0, 1526.0, "Hz"), 1000.0, "PWM frequency"),
            Param("common_anode", Boolean(), False, "LEDs lit while the output is low"),
        ),
        fields=("leds",),
    ),
    _leds,
    simulate=_simulate,
    probe=_probe,
    check_together=_all_call,
    service=HardwareLeds,
)
