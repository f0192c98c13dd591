"""The robot config's buses: ``i2c: {kind: i2c, number: 1}``, an SPI node, a serial port."""

from __future__ import annotations

from typing import Any

from engine.files.yaml_source import YMap, YValue
from engine.hardware.chips.fields import ConfigChecks
from engine.hardware.config import BUS_KINDS, BusConfig
from engine.values.params import REQUIRED, Choice, Integer, Param, Text

BUS_FIELDS: dict[str, tuple[Param[Any], ...]] = {
    "i2c": (Param("number", Integer(0, 255), REQUIRED, "N of /dev/i2c-N"),),
    "spi": (
        Param("number", Integer(0, 255), REQUIRED, "N of /dev/spidevN.C"),
        Param("chip_select", Integer(0, 255), 0, "C of /dev/spidevN.C"),
    ),
    "serial": (
        Param("port", Text(), REQUIRED, "the port, e.g. /dev/ttyACM0"),
        Param("baudrate", Integer(300, 4_000_000), 115200, "baud rate (ignored over USB)"),
    ),
}


def check_buses(checker: ConfigChecks, document: YMap) -> dict[str, BusConfig]:
    """The config's ``buses:``, each checked; problems are added with their places."""
    raw = document.get("buses")
    if raw is None:
        checker.problems.add(
            document.mark, "a robot config needs 'buses:'", "e.g. i2c: {kind: i2c, number: 1}"
        )
        return {}
    section = checker.mapping(raw, "'buses'", "e.g. i2c: {kind: i2c, number: 1}")
    buses: dict[str, BusConfig] = {}
    for name, body in section.items() if section is not None else ():
        bus = _bus(checker, name, body)
        if bus is not None:
            buses[name] = bus
    _one_entry_per_adapter(checker, buses)
    return buses


def _one_entry_per_adapter(checker: ConfigChecks, buses: dict[str, BusConfig]) -> None:
    """Two entries for one device file would be two bus managers on one adapter."""
    first: dict[str, BusConfig] = {}
    for bus in buses.values():
        holder = first.get(bus.path)
        if holder is None:
            first[bus.path] = bus
            continue
        checker.problems.add(
            bus.mark,
            f"bus {bus.name!r} is {bus.path}, like bus {holder.name!r} "
            f"(line {holder.mark.line}): one adapter needs one bus entry, or two owners "
            "would use it at once",
            f"remove {bus.name!r} and put its devices on bus {holder.name!r}",
        )


def _bus(checker: ConfigChecks, name: str, body: YValue) -> BusConfig | None:
    raw = checker.mapping(body, f"bus {name!r}", "e.g. {kind: i2c, number: 1}")
    if raw is None:
        return None
    kind_raw = raw.get("kind")
    if kind_raw is None:
        checker.problems.add(raw.mark, f"bus {name!r} needs 'kind'", "i2c, spi or serial")
        return None
    kind = checker.convert(Choice(BUS_KINDS), kind_raw, "kind")
    if kind is None:
        return None
    params = BUS_FIELDS[kind]
    checker.unknown_fields(raw, ["kind", *(p.name for p in params)], f"{kind} bus")
    values = checker.fields(raw, params, f"{kind} bus {name!r}")
    if values is None:
        return None
    return BusConfig(name=name, kind=kind, mark=raw.mark, **values)
