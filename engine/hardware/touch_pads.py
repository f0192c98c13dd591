"""Touch pads by name: the names a robot config gives its MPR121's electrodes, checked
where a person names a pad (a tree's ``OnTouch``, a scenario's ``touch``)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from engine.drivers.mpr121_registers import PADS
from engine.files.problems import Problem
from engine.hardware.config import DeviceConfig, RobotConfig
from engine.values.param_problems import did_you_mean


def default_pad_name(electrode: int) -> str:
    """The name of an electrode the config does not name: ``pad_3``."""
    return f"pad_{electrode}"


def pad_names(device: DeviceConfig) -> tuple[str, ...]:
    """Every electrode's name, electrode 0 first (the config's, else ``pad_N``)."""
    named = device.pad_names
    return tuple(
        named[index] if index < len(named) else default_pad_name(index) for index in range(PADS)
    )


def robot_pad_names(config: RobotConfig) -> tuple[str, ...]:
    """The names of the robot's touch pads (its first touch chip's; none without one)."""
    touch = config.with_role("touch")
    return pad_names(touch[0]) if touch else ()


def unknown_pad(name: str, names: tuple[str, ...], config: RobotConfig) -> tuple[str, str]:
    hint = did_you_mean(name, list(names)) or (
        "pads: " + ", ".join(names) if names else "the robot has no touch pads"
    )
    return f"no touch pad {name!r} on the robot of {config.path}", hint


def name_scenario_pads(events: Iterable[Any], config: RobotConfig) -> list[Problem]:
    """Each ``touch`` event's pad as its electrode number (``pad``) and its name
    (``pad_name``) on ``config``'s vest; a problem at the event for a name the robot's
    pads do not have."""
    names = robot_pad_names(config)
    problems: list[Problem] = []
    for event in events:
        if event.kind != "touch":
            continue
        pad = event.value["pad"]
        if isinstance(pad, str):
            if pad not in names:
                problems.append(Problem(event.mark, *unknown_pad(pad, names, config)))
                continue
            event.value["pad"] = names.index(pad)
        index = event.value["pad"]
        event.value["pad_name"] = names[index] if index < len(names) else default_pad_name(index)
    return problems
