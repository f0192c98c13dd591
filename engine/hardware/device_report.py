"""What ``vest devices`` shows: each configured device, whether it answers as itself, and one
reading.

:func:`describe_devices` probes every device of a built :class:`~engine.hardware.assembly.
Hardware` (on the robot's buses or on the simulated vest, the same way) and returns one
:class:`DeviceRow` per device, in config order. It waits for answers (an SRF02 ranging
takes 66 ms), so it is for the command line, not for a running robot's ticks.
"""

from __future__ import annotations

from dataclasses import dataclass

from engine.drivers.bus_errors import describe_exception
from engine.errors import VestError
from engine.hardware.assembly import probe_for
from engine.hardware.chips import default_chips
from engine.hardware.config import DeviceConfig
from engine.hardware.readings import Staged
from engine.hardware.robot_hardware import Hardware

COLUMNS = ("device", "chip", "where", "identity", "reading")
WAIT_S = 2.0  # real seconds to wait for one answer on a busy threaded bus


@dataclass(frozen=True)
class DeviceRow:
    """One device: ``ok`` when it answered as the chip it should be."""

    name: str
    chip: str
    where: str
    ok: bool
    identity: str
    reading: str

    def cells(self) -> tuple[str, str, str, str, str]:
        return (self.name, self.chip, self.where, self.identity, self.reading)


def describe_devices(hardware: Hardware) -> list[DeviceRow]:
    """Probe every configured device and read it once."""
    return [_row(hardware, device) for device in hardware.config.devices.values()]


def format_rows(rows: list[DeviceRow]) -> str:
    """The rows as an aligned text table with a header."""
    table = [COLUMNS, *(row.cells() for row in rows)]
    widths = [max(len(line[column]) for line in table) for column in range(len(COLUMNS))]
    return "\n".join(
        "  ".join(cell.ljust(width) for cell, width in zip(line, widths, strict=True)).rstrip()
        for line in table
    )


def _row(hardware: Hardware, device: DeviceConfig) -> DeviceRow:
    where = device.where(hardware.config.bus_of(device))
    problem = hardware.startup_problems.get(device.name)
    try:
        identity = _identity(hardware, device)
        reading = _reading(hardware, device)
    except Exception as error:
        why = str(error) if isinstance(error, VestError) else describe_exception(error)
        if problem is not None and problem != why:
            why = f"{why} (at start-up: {problem})"
        return DeviceRow(device.name, device.chip, where, False, f"no: {why}", "-")
    return DeviceRow(device.name, device.chip, where, True, identity, reading)


def _identity(hardware: Hardware, device: DeviceConfig) -> str:
    """Ask the chip who it is: its probe (identity registers), or the Maestro's errors."""
    handle = hardware.handles.get(device.name)
    if handle is None:
        raise OSError(hardware.startup_problems.get(device.name, "not started"))
    if device.role == "servos":
        errors = handle.call(lambda maestro: maestro.get_errors(), timeout_s=WAIT_S)
        return "answers as a Maestro; errors: " + (", ".join(errors) or "none")
    probe = probe_for(device)
    if probe is not None:
        handle.call(probe, timeout_s=WAIT_S)
    return f"answers as {device.chip}"


def _reading(hardware: Hardware, device: DeviceConfig) -> str:
    role = device.role
    if device.polled:
        writes = hardware.poller(device.name).read_now(fresh=True)
        return _show_writes(device, writes)
    if role == "leds" and hardware.leds is not None:
        return hardware.leds.read_now()
    if role == "servos" and hardware.servos is not None:
        return hardware.servos.read_now()
    if role == "temperature" and hardware.sensors.temperature is not None:
        return hardware.sensors.temperature.read_now()
    if role == "ultrasound" and hardware.sensors.ultrasound is not None:
        return hardware.sensors.ultrasound.read_now()
    if role == "mux":
        mux = hardware.muxes.get(device.name)
        if mux is None:
            raise OSError(hardware.startup_problems.get(device.name, "did not start"))
        handle = hardware.handles[device.name]
        selected = handle.call(lambda bus: mux.selected())
        return "channels selected: " + (", ".join(map(str, selected)) or "none")
    raise OSError(hardware.startup_problems.get(device.name, "not started"))


def _show_writes(device: DeviceConfig, writes: list[Staged]) -> str:
    kind = default_chips().get(device.chip)
    if kind is not None and kind.show is not None:
        return kind.show(device, writes)
    return ", ".join(f"{w.key}={w.value!r}" for w in writes)
