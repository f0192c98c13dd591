"""The XYZ Interactive ZX gesture sensor: swipes and hovers, named as the config says."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from engine.blackboard.catalogue import GESTURE_LAST
from engine.drivers import zx_gesture_registers as registers
from engine.drivers.zx_gesture import ZXGesture
from engine.hardware.chips.fields import ChipFields
from engine.hardware.chips.kind import ChipKind, SimPlacement, expect_identity
from engine.hardware.config import ENGINE_GESTURES, ZX_GESTURES, ChipSpec, DeviceConfig
from engine.hardware.managed_buses import ManagedI2C
from engine.hardware.readings import PollParts, PollSetup, Staged
from engine.sim.zx_gesture import SimZXGesture
from engine.values.param_problems import did_you_mean
from engine.values.params import Choice


def _gesture_names_check(fields: ChipFields) -> dict[str, str] | None:
    section = fields.checker.mapping(
        fields.raw.get("gesture_names"), "'gesture_names'", "e.g. {swipe_left: wave}"
    )
    names = {gesture: gesture for gesture in ZX_GESTURES}
    if section is None:
        return None if "gesture_names" in fields.raw else names
    ok = True
    for reported, value in section.items():
        if reported not in ZX_GESTURES:
            fields.checker.problems.add(
                section.key_marks[reported],
                f"the ZX sensor reports no gesture {reported!r}",
                did_you_mean(reported, ZX_GESTURES) or "it reports " + ", ".join(ZX_GESTURES),
            )
            ok = False
            continue
        engine_name = fields.checker.convert(Choice(ENGINE_GESTURES), value, reported)
        if engine_name is None:
            ok = False
        else:
            names[reported] = engine_name
    return names if ok else None


def _gesture_names(fields: ChipFields) -> dict[str, Any] | None:
    names = _gesture_names_check(fields)
    return None if names is None else {"gesture_names": names}


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    assert device.address is not None
    vest.attach_i2c(device, SimZXGesture(vest.clock, device.address))


def _probe(address: int) -> Callable[[Any], object]:
    return lambda bus: expect_identity(
        "ZX model", bus.read_byte_data(address, registers.MODEL), registers.MODEL_ID
    )


def _poll(setup: PollSetup) -> PollParts:
    key = setup.device.keys["gesture"]
    names = setup.device.gesture_names

    def connect() -> ZXGesture:
        return ZXGesture(ManagedI2C(setup.handle), address=setup.address)

    def read(driver: ZXGesture) -> list[Staged]:
        gesture = driver.read_gesture()
        if gesture is None:
            return []
        return [Staged(key, names.get(gesture, gesture), event=True)]

    return PollParts(connect, read, [])


def _show(device: DeviceConfig, writes: Sequence[Staged]) -> str:
    return "gesture: " + (str(writes[0].value) if writes else "none")


KIND = ChipKind(
    ChipSpec(
        "zx_gesture",
        "XYZ Interactive ZX gesture sensor",
        "i2c",
        "gesture",
        addresses=(0x10, 0x11),
        default_address=0x10,
        default_rate_hz=20.0,
        outputs={"gesture": GESTURE_LAST},
        fields=("gesture_names",),
    ),
    _gesture_names,
    simulate=_simulate,
    probe=_probe,
    poll=_poll,
    show=_show,
)
