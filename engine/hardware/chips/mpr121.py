"""The NXP MPR121 capacitive touch chip: 12 pads, polled."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from engine.blackboard.catalogue import TOUCH_ANY, TOUCH_PADS
from engine.drivers import mpr121 as driver
from engine.drivers.mpr121 import MPR121, PADS, check_thresholds
from engine.drivers.sim.mpr121 import SimMPR121
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.kind import ChipKind, SimPlacement
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.hardware.managed_buses import ManagedI2C
from engine.hardware.readings import PollParts, PollSetup, Staged
from engine.values.params import Integer, Param


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    vest.attach_i2c(device, SimMPR121(device.address))


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: bus.read_byte_data(address, driver.CONFIG2)


def _poll(setup: PollSetup) -> PollParts:
    device = setup.device
    pads_key, any_key = device.keys["pads"], device.keys["any"]

    def connect() -> MPR121:
        return MPR121(ManagedI2C(setup.handle), address=setup.address, **device.options)

    def read(driver: MPR121) -> list[Staged]:
        pads = driver.touched()
        return [Staged(pads_key, pads), Staged(any_key, any(pads))]

    return connect, read, [Staged(pads_key, [False] * PADS), Staged(any_key, False)]


def _show(device: DeviceConfig, writes: Sequence[Staged]) -> str:
    pads = next((w.value for w in writes if isinstance(w.value, list)), [])
    touched = [str(pad) for pad, on in enumerate(pads) if on]
    return "pads touched: " + (", ".join(touched) or "none")


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
        outputs={"pads": TOUCH_PADS, "any": TOUCH_ANY},
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
    check_fields=_check_thresholds,
)
