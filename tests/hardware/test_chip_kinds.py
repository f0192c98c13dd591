"""The chip-kind registry: each chip declared in one module, the config checker asks it."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.files.yaml_source import load_yaml
from engine.hardware.chips import ChipKind, ChipRegistry, default_chips
from engine.hardware.config import ChipSpec
from engine.hardware.config_check import ConfigChecker


def test_every_shipped_chip_has_its_kind() -> None:
    assert default_chips().names == [
        "mpr121", "ads1115", "mcp3008", "vl53l0x", "zx_gesture",
        "srf02", "mcp9808", "pca9685", "maestro", "tca9548a",
    ]  # fmt: skip


def test_every_shipped_chip_kind_has_a_simulated_model() -> None:
    assert [kind.name for kind in default_chips() if kind.simulate is None] == []


def test_every_shipped_i2c_chip_kind_knows_how_to_probe_for_itself() -> None:
    i2c = [kind for kind in default_chips() if kind.spec.bus_kind == "i2c"]
    assert [kind.name for kind in i2c if kind.probe is None] == []


def test_the_polled_chip_kinds_are_the_ones_with_a_poller() -> None:
    chips = default_chips()
    assert [k.name for k in chips if k.poll is not None] == [k.name for k in chips if k.spec.polled]


def test_chips_read_on_request_or_commanded_bring_their_service() -> None:
    # the Maestro owns its serial port, so the assembly builds its service itself
    on_request = [
        k for k in default_chips() if k.spec.role in ("temperature", "ultrasound", "leds")
    ]
    assert [k.name for k in on_request if k.service is None] == []


def test_a_chip_kind_registered_twice_is_refused() -> None:
    kind = ChipKind(ChipSpec("mpr121", "again", "i2c", "touch"))
    with pytest.raises(ValueError, match="registered twice"):
        ChipRegistry([kind, kind])


def test_a_new_chip_kind_is_known_to_the_config_checker_by_registering_it(
    tmp_path: Path,
) -> None:
    chips = default_chips()
    chips.add(
        ChipKind(
            ChipSpec("hdc1080", "TI HDC1080 humidity", "i2c", "humidity", addresses=(0x40,),
                     default_address=0x40)
        )
    )  # fmt: skip
    path = tmp_path / "robot.yaml"
    path.write_text(
        "name: r\nbuses:\n  i2c: {kind: i2c, number: 1}\ndevices:\n  air: {chip: hdc1080}\n"
    )
    config = ConfigChecker("robot.yaml", path, default_catalogue(), chips).check(load_yaml(path))
    assert config.devices["air"].chip == "hdc1080"
    assert config.devices["air"].address == 0x40
