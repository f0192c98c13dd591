"""The ST VL53L0X time-of-flight sensor: one side, re-addressed by XSHUT or behind a mux."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from engine.drivers import vl53l0x as driver
from engine.drivers.bus_manager import Priority
from engine.drivers.vl53l0x import VL53L0X
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.kind import ChipKind, DevicesTogether, SimPlacement, expect_identity
from engine.hardware.config import SIDES, VL53L0X_BOOT_ADDRESS, ChipSpec, DeviceConfig, hex_address
from engine.hardware.managed_buses import ManagedI2C
from engine.hardware.readings import PollParts, PollSetup, Staged
from engine.sim.vl53l0x import SimVL53L0X
from engine.values.params import Choice, Integer, Number, Param, Text


def _range_place(fields: ChipFields) -> dict[str, Any] | None:
    values: dict[str, Any] = {"side": None, "xshut": None, "mux": None, "mux_channel": None}
    ok = True
    side_raw = fields.raw.get("side")
    if side_raw is None:
        fields.checker.problems.add(
            fields.raw.mark,
            f"vl53l0x device {fields.name!r} needs 'side'",
            "left, center or right: the way it looks",
        )
        ok = False
    else:
        values["side"] = fields.checker.convert(Choice(SIDES), side_raw, "side")
        ok = ok and values["side"] is not None
    xshut_raw = fields.raw.get("xshut")
    if xshut_raw is not None:
        values["xshut"] = fields.checker.convert(Integer(0, 1023), xshut_raw, "xshut")
        ok = ok and values["xshut"] is not None
    mux_raw, channel_raw = fields.raw.get("mux"), fields.raw.get("channel")
    if mux_raw is not None:
        values["mux"] = fields.checker.convert(Text(), mux_raw, "mux")
        ok = ok and values["mux"] is not None
        if channel_raw is None:
            fields.checker.problems.add(
                fields.raw.key_marks["mux"],
                f"device {fields.name!r} names a mux but no 'channel'",
                "the TCA9548A channel it is wired to, 0..7",
            )
            ok = False
    if channel_raw is not None:
        if mux_raw is None:
            fields.checker.problems.add(
                fields.raw.key_marks["channel"],
                "'channel' is a TCA9548A channel, but no 'mux' is named",
                "add mux: NAME of the tca9548a device",
            )
            ok = False
        values["mux_channel"] = fields.checker.convert(Integer(0, 7), channel_raw, "channel")
        ok = ok and values["mux_channel"] is not None
    if xshut_raw is not None and mux_raw is not None:
        fields.checker.problems.add(
            fields.raw.key_marks["xshut"],
            "a VL53L0X is either re-addressed through its XSHUT line or behind a mux",
            "remove 'xshut' or 'mux'",
        )
        ok = False
    return values if ok else None


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    bus = vest.i2c_bus_for(device)
    if device.xshut is not None:  # in standby until the start-up chain switches it on
        vest.keep(device, SimVL53L0X(vest.clock, bus, xshut_high=False), bus)
    else:
        assert device.address is not None
        vest.keep(device, SimVL53L0X(vest.clock, bus, device.address), bus)


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: expect_identity(
        "VL53L0X model ID",
        bus.read_byte_data(address, driver.IDENTIFICATION_MODEL_ID),
        driver.IDENTITY[0],
    )


def _poll(setup: PollSetup) -> PollParts:
    device, handle, clock, chain = setup.device, setup.handle, setup.clock, setup.chain
    key = device.keys["range"]
    address = setup.address

    def connect() -> VL53L0X:
        """The chip brought up and ranging back to back: a poll then reads the latest
        measurement (at most a timing budget old) without waiting for one."""
        try:
            driver = VL53L0X(ManagedI2C(handle), address=address, clock=clock, **device.options)
        except OSError:
            # Not at its address: power-cycled (back at 0x29), or left in standby at start-up.
            if chain is None or not chain.may_reboot(device.name):
                raise
            chain.reboot(device.name)
            # Ahead of the polls, which the bus manager refuses while it has the chip offline.
            bus = ManagedI2C(handle, priority=Priority.REQUEST)
            driver = VL53L0X(bus, address=address, clock=clock, **device.options)
            driver.start_continuous()
            bus.priority = Priority.POLL
            return driver
        driver.start_continuous()
        return driver

    def read(driver: VL53L0X) -> list[Staged]:
        distance_mm = driver.read_range_mm()
        return [Staged(key, None if distance_mm is None else float(distance_mm))]

    return PollParts(connect, read, [Staged(key, None)], release=VL53L0X.stop_continuous)


def _show(device: DeviceConfig, writes: Sequence[Staged]) -> str:
    value = writes[0].value if writes else None
    return "nothing in range" if value is None else f"{value:.0f} mm"


def _range_chains(checks: DevicesTogether, mine: list[DeviceConfig]) -> None:
    """VL53L0X chips all boot at 0x29: each needs XSHUT or a mux, but for one at 0x29."""
    lines: dict[int, DeviceConfig] = {}
    for device in checks.devices.values():
        if device.xshut is None:
            continue
        holder = lines.get(device.xshut)
        if holder is not None:
            checks.problems.add(
                checks.mark(device, "xshut"),
                f"GPIO line {device.xshut} is already the XSHUT of {holder.name!r}",
                "each VL53L0X needs its own XSHUT line",
            )
        lines[device.xshut] = device
    for bus in checks.buses.values():
        direct = [d for d in mine if d.bus == bus.name and d.mux is None]
        unswitched = [d for d in direct if d.xshut is None]
        for device in unswitched:
            if device.address != VL53L0X_BOOT_ADDRESS:
                checks.problems.add(
                    checks.mark(device, "address"),
                    f"VL53L0X {device.name!r} has no XSHUT line, so it boots at 0x29 and "
                    f"cannot be moved to {hex_address(device.address)}",
                    "add 'xshut: LINE' or use address 0x29",
                )
        if unswitched and len(direct) > 1:
            checks.problems.add(
                checks.mark(unswitched[-1], "xshut"),
                f"{len(direct)} VL53L0X share bus {bus.name!r} but "
                f"{', '.join(repr(d.name) for d in unswitched)} has no XSHUT line; every "
                "chip boots at 0x29",
                "give each its own XSHUT line, or put them behind a TCA9548A",
            )
        chained = [d for d in direct if d.xshut is not None]
        for device in chained[:-1]:
            if device.address == VL53L0X_BOOT_ADDRESS:
                checks.problems.add(
                    checks.mark(device, "address"),
                    f"VL53L0X {device.name!r} stays at 0x29, where the chips switched on "
                    "after it boot",
                    "give it another address, or list it last",
                )


KIND = ChipKind(
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
    _range_place,
    simulate=_simulate,
    probe=_probe,
    poll=_poll,
    show=_show,
    check_together=_range_chains,
)
