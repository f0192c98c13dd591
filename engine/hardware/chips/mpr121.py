"""The NXP MPR121 capacitive touch chip: 12 pads, polled."""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from typing import Any

from engine.blackboard.catalogue import TOUCH_ANY, TOUCH_PADS, TOUCH_PAT, TOUCH_TOUCHED
from engine.drivers.mpr121 import MPR121, check_thresholds
from engine.drivers.mpr121_registers import CONFIG2, PADS
from engine.files.yaml_source import YList, describe
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.kind import ChipKind, SimPlacement
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.hardware.managed_buses import ManagedI2C
from engine.hardware.readings import PollParts, PollSetup, Staged
from engine.hardware.touch_pads import default_pad_name, pad_names
from engine.sim.mpr121 import SimMPR121
from engine.values.params import Integer, Param

_PAD_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    vest.attach_i2c(device, SimMPR121(device.address))


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: bus.read_byte_data(address, CONFIG2)


def _poll(setup: PollSetup) -> PollParts:
    """Each poll stages the 12 pads, whether any is touched, the names of those touched,
    and a ``pat`` event naming each pad that was not touched at the poll before (a hand
    resting on a pad is one pat; after the chip was offline, a resting hand pats anew)."""
    device = setup.device
    keys = device.keys
    names = pad_names(device)
    before = [False] * PADS

    def connect() -> MPR121:
        before[:] = [False] * PADS
        return MPR121(ManagedI2C(setup.handle), address=setup.address, **device.options)

    def read(driver: MPR121) -> list[Staged]:
        pads = driver.touched()
        touched = [names[pad] for pad, on in enumerate(pads) if on]
        writes = _fed(keys, pads=pads, any=bool(touched), touched=touched)
        if keys.get("pat"):
            writes += [
                Staged(keys["pat"], names[pad], event=True)
                for pad, on in enumerate(pads)
                if on and not before[pad]
            ]
        before[:] = pads
        return writes

    nothing: list[str] = []
    return PollParts(connect, read, _fed(keys, pads=[False] * PADS, any=False, touched=nothing))


def _fed(keys: dict[str, str], **values: Any) -> list[Staged]:
    """The writes of the readings this device feeds a key (a device built in code may
    feed only some)."""
    return [Staged(keys[output], value) for output, value in values.items() if keys.get(output)]


def _show(device: DeviceConfig, writes: Sequence[Staged]) -> str:
    pads: list[bool] = next((w.value for w in writes if w.key == device.keys["pads"]), [])
    names = pad_names(device)
    touched = [f"{pad} ({names[pad]})" for pad, on in enumerate(pads) if on]
    return "pads touched: " + (", ".join(touched) or "none")


def _check_pad_names(fields: ChipFields) -> tuple[str, ...] | None:
    """``pad_names``: a list of names, electrode 0 first; lower-case words, each once."""
    raw = fields.raw.get("pad_names")
    if raw is None:
        return ()
    example = "e.g. pad_names: [left_shoulder, right_shoulder, upper_back]"
    if not isinstance(raw, YList):
        fields.checker.problems.add(
            raw.mark, f"'pad_names' must be a list, electrode 0 first, got {describe(raw)}", example
        )
        return None
    if len(raw) > PADS:
        fields.checker.problems.add(
            raw.mark, f"'pad_names' names {len(raw)} pads; the MPR121 has {PADS}", example
        )
        return None
    names: list[str] = []
    for electrode, item in enumerate(raw):
        name = item.value if hasattr(item, "value") else None
        if not isinstance(name, str) or not _PAD_NAME.match(name):
            fields.checker.problems.add(
                item.mark,
                f"pad name {describe(item)} (electrode {electrode}) must be a lower-case word "
                "like left_shoulder",
                "letters, digits and _, starting with a letter",
            )
            return None
        if re.fullmatch(r"pad_[0-9]+", name) and name != default_pad_name(electrode):
            fields.checker.problems.add(
                item.mark,
                f"pad name {name!r} (electrode {electrode}) is the name of another electrode",
                "name it after where it is, e.g. upper_back",
            )
            return None
        if name in names:
            fields.checker.problems.add(
                item.mark,
                f"pad name {name!r} is given to electrodes {names.index(name)} and {electrode}",
                "give each pad its own name",
            )
            return None
        names.append(name)
    return tuple(names)


def _check_fields(fields: ChipFields) -> dict[str, Any] | None:
    thresholds = _check_thresholds(fields)
    names = _check_pad_names(fields)
    if thresholds is None or names is None:
        return None
    return {"pad_names": names}


def _check_thresholds(fields: ChipFields) -> dict[str, Any] | None:
    """The driver refuses a release threshold above the touch threshold: say so now, with
    the place, rather than at start-up."""
    options = fields.options
    if options is None:
        return {}
    try:
        check_thresholds(options["touch_threshold"], options["release_threshold"])
    except ValueError as error:
        raw = fields.raw
        where = raw.get("release_threshold") or raw.get("touch_threshold") or raw
        fields.checker.problems.add(where.mark, str(error), "release_threshold <= touch_threshold")
        return None
    return {}


KIND = ChipKind(
    ChipSpec(
        "mpr121",
        "NXP MPR121 capacitive touch, 12 pads",
        "i2c",
        "touch",
        addresses=tuple(range(0x5A, 0x5E)),
        default_address=0x5A,
        default_rate_hz=20.0,
        outputs={
            "pads": TOUCH_PADS,
            "any": TOUCH_ANY,
            "touched": TOUCH_TOUCHED,
            "pat": TOUCH_PAT,
        },
        fields=("pad_names",),
        options=(
            Param("touch_threshold", Integer(1, 255), 12, "touch threshold, counts"),
            Param("release_threshold", Integer(0, 255), 6, "release threshold, counts"),
        ),
    ),
    simulate=_simulate,
    probe=_probe,
    poll=_poll,
    show=_show,
    list_lengths=(("pads", PADS),),
    check_fields=_check_fields,
)
