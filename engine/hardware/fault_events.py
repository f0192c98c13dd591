"""A scenario's ``unplug`` and ``fault`` events checked against the robot config."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from engine.files.problems import Problem
from engine.hardware.config import CAMERA_NAME, RobotConfig
from engine.hardware.sim_vest import SPI_FAULTS
from engine.values.param_problems import did_you_mean


def check_fault_events(events: Iterable[Any], config: RobotConfig) -> list[Problem]:
    """Problems with the ``unplug`` and ``fault`` events of a scenario against ``config``.

    ``events`` are :class:`~engine.scenario.scenario_file.ScenarioEvent` (``kind``,
    ``value`` with ``device``, ``kind`` and ``seconds``, ``mark``); each problem names the
    event's place: an unknown device (with the nearest name), a device the simulation
    cannot fail (the Maestro), a fault an SPI device cannot have.
    """
    problems: list[Problem] = []
    for event in events:
        if event.kind not in ("unplug", "fault"):
            continue
        name = event.value["device"]
        device = config.devices.get(name)
        if device is None and config.camera is not None and name == CAMERA_NAME:
            if event.value.get("kind", "unplugged") != "unplugged":
                problems.append(
                    Problem(event.mark, f"the {name} can be unplugged, not {event.value['kind']!r}")
                )
            continue
        if device is None:
            hint = did_you_mean(name, list(config.devices))
            known = "devices: " + ", ".join(config.devices)
            problems.append(
                Problem(event.mark, f"no device {name!r} in {config.path}", hint or known)
            )
            continue
        kind = event.value.get("kind", "unplugged")
        bus = config.bus_of(device)
        if bus.kind == "serial":
            problems.append(
                Problem(
                    event.mark,
                    f"{name!r} ({device.chip}) cannot be failed in the simulation",
                    "the simulated vest fails I2C and SPI devices",
                )
            )
        elif bus.kind == "spi" and kind not in SPI_FAULTS:
            problems.append(
                Problem(
                    event.mark,
                    f"{name!r} is on SPI: it can be {' or '.join(SPI_FAULTS)}, not {kind!r}",
                )
            )
    return problems
