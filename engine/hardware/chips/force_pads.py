"""Force pads on an ADC (ADS1115, MCP3008): each pad's channel, key and volts -> newtons
calibration table, as the robot config names them."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from engine.blackboard.catalogue import force_key
from engine.drivers.force_calibration import ForceCalibration
from engine.files.yaml_source import YList, YValue, describe, plain
from engine.hardware.chips.fields import ChipFields
from engine.hardware.config import DeviceConfig, ForcePad
from engine.hardware.readings import PollParts, Staged
from engine.values.params import REQUIRED, Integer, Key, Number, Param


class ForceReader(Protocol):
    """An ADC driver that reads one input in volts (ADS1115, MCP3008)."""

    def read_volts(self, channel: int) -> float: ...


DEFAULT_SQUEEZE_N = 3.0
SQUEEZE = Param(
    "squeeze_n",
    Number(0.1, 100.0, "N"),
    DEFAULT_SQUEEZE_N,
    "a squeeze event when a pad's force rises past this; again once it fell below half",
)


def force_fields(fields: ChipFields, channels: int) -> dict[str, Any] | None:
    """The pads and the squeeze threshold of a force chip's config entry."""
    pads = force_pads(fields, channels)
    values = fields.checker.fields(fields.raw, (SQUEEZE,), f"device {fields.name!r}")
    if pads is None or values is None:
        return None
    return {"pads": pads, "squeeze_n": values["squeeze_n"]}


def force_pads(fields: ChipFields, channels: int) -> tuple[ForcePad, ...] | None:
    section = fields.checker.mapping(
        fields.raw.get("pads"),
        "'pads'",
        "e.g. pads: {left: {channel: 0, calibration: [[0.0, 0.0], [3.0, 6.0]]}}",
    )
    if section is None:
        if "pads" not in fields.raw:
            fields.checker.problems.add(
                fields.raw.mark,
                f"{fields.spec.chip} device {fields.name!r} needs 'pads'",
                "e.g. pads: {left: {channel: 0, calibration: [[0.0, 0.0], [3.0, 6.0]]}}",
            )
        return None
    pads: list[ForcePad] = []
    used: dict[int, str] = {}
    ok = True
    for pad_name, body in section.items():
        pad = _pad(fields, pad_name, body, channels)
        if pad is None:
            ok = False
            continue
        if pad.channel in used:
            fields.checker.problems.add(
                pad.mark,
                f"pad {pad_name!r} uses channel {pad.channel}, already used by pad "
                f"{used[pad.channel]!r}",
                "give each pad its own channel",
            )
            ok = False
        used[pad.channel] = pad_name
        pads.append(pad)
    if not pads and ok:
        fields.checker.problems.add(section.mark, "'pads' lists no pad", "e.g. left: {channel: 0}")
        ok = False
    return tuple(pads) if ok else None


def _pad(fields: ChipFields, pad_name: str, body: YValue, channels: int) -> ForcePad | None:
    raw = fields.checker.mapping(body, f"pad {pad_name!r}", "e.g. {channel: 0, calibration: [...]}")
    if raw is None:
        return None
    fields.checker.unknown_fields(raw, ("channel", "key", "calibration"), "pad")
    values = fields.checker.fields(
        raw,
        (
            Param("channel", Integer(0, channels - 1), REQUIRED, "ADC input"),
            Param("key", Key(), force_key(pad_name), "blackboard key"),
        ),
        f"pad {pad_name!r}",
    )
    table_raw = raw.get("calibration")
    if table_raw is None:
        fields.checker.problems.add(
            raw.mark,
            f"pad {pad_name!r} needs 'calibration'",
            "a volts -> newtons table, e.g. [[0.0, 0.0], [0.83, 0.2], [3.0, 6.0]]",
        )
        return None
    table = _calibration(fields, table_raw)
    if values is None or table is None:
        return None
    if fields.checker.ctx.catalogue.lookup(values["key"]) is None:  # the default key
        fields.checker.problems.add(
            raw.mark,
            f"pad {pad_name!r} would feed {values['key']}, which is not a blackboard key",
            "name its 'key', e.g. /sensors/force/left_n",
        )
        return None
    return ForcePad(pad_name, values["channel"], values["key"], table, raw.mark)


def _calibration(fields: ChipFields, raw: YValue) -> tuple[tuple[float, float], ...] | None:
    example = "pairs of [volts, newtons], e.g. [[0.0, 0.0], [0.83, 0.2], [3.0, 6.0]]"
    if not isinstance(raw, YList):
        fields.checker.problems.add(
            raw.mark, f"'calibration' must be a list, got {describe(raw)}", example
        )
        return None
    points: list[tuple[float, float]] = []
    ok = True
    for index, item in enumerate(raw):
        value = plain(item)
        if (
            not isinstance(value, list)
            or len(value) != 2
            or any(isinstance(v, bool) or not isinstance(v, int | float) for v in value)
        ):
            fields.checker.problems.add(
                item.mark,
                f"calibration point {index + 1} must be [volts, newtons], got {describe(item)}",
                example,
            )
            ok = False
            continue
        volts, newtons = float(value[0]), float(value[1])
        if not (math.isfinite(volts) and math.isfinite(newtons)):
            fields.checker.problems.add(
                item.mark,
                f"calibration point {index + 1} is [{volts:g}, {newtons:g}]: volts and "
                "newtons must be finite numbers",
                example,
            )
            ok = False
            continue
        if newtons < 0:
            fields.checker.problems.add(
                item.mark, f"calibration point {index + 1} has negative force {newtons:g} N"
            )
            ok = False
            continue
        if points and volts <= points[-1][0]:
            fields.checker.problems.add(
                item.mark,
                f"calibration is not increasing: point {index + 1} has {volts:g} V after "
                f"{points[-1][0]:g} V",
                "list the points by strictly increasing volts",
            )
            ok = False
        elif points and newtons < points[-1][1]:
            fields.checker.problems.add(
                item.mark,
                f"calibration is not increasing: point {index + 1} has {newtons:g} N after "
                f"{points[-1][1]:g} N",
                "a harder squeeze must never read as a lighter one",
            )
            ok = False
        points.append((volts, newtons))
    if ok and len(points) < 2:
        fields.checker.problems.add(
            raw.mark, f"calibration needs at least two points, got {len(points)}", example
        )
        ok = False
    return tuple(points) if ok else None


def force_poll(device: DeviceConfig, connect: Callable[[], ForceReader]) -> PollParts:
    """The poller parts of an ADC's force pads: each pad's volts through its calibration,
    and a ``squeeze`` event naming a pad whose force rose past ``squeeze_n`` (armed again
    once it fell below half of that, so a held squeeze is one event)."""
    calibrations = [(pad, ForceCalibration(pad.calibration)) for pad in device.pads]
    squeeze_n = device.squeeze_n if device.squeeze_n is not None else DEFAULT_SQUEEZE_N
    squeeze_key = device.keys.get("squeeze")
    squeezed = {pad.name: False for pad in device.pads}

    def reconnect() -> ForceReader:
        squeezed.update(dict.fromkeys(squeezed, False))
        return connect()

    def read(driver: ForceReader) -> list[Staged]:
        writes: list[Staged] = []
        events: list[Staged] = []
        for pad, calibration in calibrations:
            newtons = calibration.newtons(driver.read_volts(pad.channel))
            writes.append(Staged(pad.key, newtons))
            if newtons >= squeeze_n and not squeezed[pad.name]:
                squeezed[pad.name] = True
                if squeeze_key:
                    events.append(Staged(squeeze_key, pad.name, event=True))
            elif newtons < squeeze_n / 2:
                squeezed[pad.name] = False
        return writes + events

    return PollParts(reconnect, read, [Staged(pad.key, 0.0) for pad in device.pads])


def show_forces(device: DeviceConfig, writes: Sequence[Staged]) -> str:
    """``left 6.0 N, right 0.0 N``: one reading of the pads, as ``vest devices`` prints it."""
    names = {pad.key: pad.name for pad in device.pads}
    return ", ".join(f"{names.get(w.key, w.key)} {w.value:.1f} N" for w in writes if not w.event)
