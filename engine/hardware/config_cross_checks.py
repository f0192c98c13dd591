"""The robot config's rules between devices: addresses on one bus, muxes, the keys two
devices feed, one device per on-request or actuator role, and each chip kind's own rules
across devices (its ``check_together``).
"""

from __future__ import annotations

from engine.files.problems import Mark, Problems
from engine.files.yaml_source import YMap
from engine.hardware.chips import ChipRegistry
from engine.hardware.config import BusConfig, DeviceConfig, hex_address
from engine.values.param_problems import did_you_mean


class CrossChecks:
    """Rules between devices: addresses, the All Call trap, XSHUT chains, muxes, keys."""

    def __init__(
        self,
        problems: Problems,
        chips: ChipRegistry,
        buses: dict[str, BusConfig],
        devices: dict[str, DeviceConfig],
        raws: dict[str, YMap],
    ) -> None:
        self._problems = problems
        self.chips = chips
        self.buses = buses
        self.devices = devices
        self.raws = raws

    @property
    def problems(self) -> Problems:
        return self._problems

    def mark(self, device: DeviceConfig, field_name: str) -> Mark:
        raw = self.raws[device.name]
        value = raw.entries.get(field_name)
        return value.mark if value is not None else raw.mark

    def run(self) -> None:
        self.addresses()
        self.muxes()
        for kind in self.chips:  # the rules a chip kind has for devices of its kind
            if kind.check_together is not None:
                mine = [d for d in self.devices.values() if d.chip == kind.name]
                if mine:
                    kind.check_together(self, mine)
        self.keys()
        self.singletons()

    def _line(self, device: DeviceConfig) -> str:
        return f"line {device.mark.line}"

    def addresses(self) -> None:
        """One device per address of one bus (or mux channel); one device per SPI node or port."""
        holders: dict[tuple[str, str | None, int | None, int | None], DeviceConfig] = {}
        for device in self.devices.values():
            bus = self.buses[device.bus]
            if device.address is None:
                place: tuple[str, str | None, int | None, int | None] = (bus.name, None, None, None)
            else:
                place = (bus.name, device.mux, device.mux_channel, device.address)
            holder = holders.get(place)
            if holder is not None:
                where = (
                    f"{bus.path}"
                    if device.address is None
                    else f"I2C {hex_address(device.address)} on bus {bus.name!r}"
                    + (f" ({device.mux} channel {device.mux_channel})" if device.mux else "")
                )
                self._problems.add(
                    self.mark(device, "address" if device.address is not None else "bus"),
                    f"{where} is used by both {holder.name!r} ({self._line(holder)}) and "
                    f"{device.name!r}",
                    "give each device its own address"
                    if device.address is not None
                    else "one device per SPI node or serial port",
                )
                continue
            holders[place] = device
        # A chip on the upstream bus answers on every mux channel too.
        for device in self.devices.values():
            if device.mux is None:
                continue
            upstream = holders.get((device.bus, None, None, device.address))
            if upstream is not None:
                self._problems.add(
                    self.mark(device, "address"),
                    f"I2C {hex_address(device.address)} behind {device.mux} clashes with "
                    f"{upstream.name!r} ({self._line(upstream)}) on the upstream bus",
                    "chips on the upstream bus answer on every channel; move one",
                )
        # A mux keeps its channel selected while the other mux selects one of its own.
        behind: dict[tuple[str, int | None], DeviceConfig] = {}
        for device in self.devices.values():
            if device.mux is None:
                continue
            other = behind.setdefault((device.bus, device.address), device)
            if other.mux != device.mux:
                self._problems.add(
                    self.mark(device, "address"),
                    f"I2C {hex_address(device.address)} is behind mux {device.mux!r} and, "
                    f"as {other.name!r} ({self._line(other)}), behind mux {other.mux!r} on "
                    f"the same bus {device.bus!r}: each mux keeps its channel selected, so "
                    "both chips would answer at once",
                    f"put both behind {other.mux!r} on different channels, or give one "
                    "another address",
                )

    def muxes(self) -> None:
        for device in self.devices.values():
            if device.mux is None:
                continue
            mux = self.devices.get(device.mux)
            if mux is None or mux.role != "mux":
                muxes = [d.name for d in self.devices.values() if d.role == "mux"]
                self._problems.add(
                    self.mark(device, "mux"),
                    f"{device.mux!r} is not a tca9548a device of this config",
                    did_you_mean(device.mux, muxes) or "muxes: " + (", ".join(muxes) or "none"),
                )
            elif mux.bus != device.bus:
                self._problems.add(
                    self.mark(device, "mux"),
                    f"mux {mux.name!r} is on bus {mux.bus!r}, not on {device.bus!r}",
                    f"put {device.name!r} on bus {mux.bus!r}",
                )

    def keys(self) -> None:
        feeders: dict[str, DeviceConfig] = {}
        for device in self.devices.values():
            for key in device.fed_keys:
                holder = feeders.get(key)
                if holder is not None:
                    self._problems.add(
                        device.mark,
                        f"{device.name!r} and {holder.name!r} ({self._line(holder)}) both feed "
                        f"{key}",
                        "give one of them other keys",
                    )
                feeders[key] = device

    def singletons(self) -> None:
        """The on-request sensors and the actuators are one device each."""
        for role in ("temperature", "ultrasound", "leds", "servos"):
            doing = [d for d in self.devices.values() if d.role == role]
            for device in doing[1:]:
                self._problems.add(
                    self.mark(device, "chip"),
                    f"two devices serve {role}: {doing[0].name!r} ({self._line(doing[0])}) and "
                    f"{device.name!r}",
                    "keep one",
                )
