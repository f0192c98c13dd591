"""Robot configs: what a wrong one says, with file:line:column, and what a right one holds."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from engine.files.problems import LoadError
from engine.hardware.config import RobotConfig
from engine.hardware.config_file import load_robot_config

from .conftest import ROOT

HEAD = """\
name: test
buses:
  i2c: {kind: i2c, number: 1}
  servos: {kind: serial, port: /dev/ttyACM0}
devices:
"""


def load(tmp_path: Path, devices: str, head: str = HEAD) -> RobotConfig:
    path = tmp_path / "robot.yaml"
    path.write_text(head + textwrap.indent(textwrap.dedent(devices), "  "))
    return load_robot_config(path, "robot.yaml")


def problems(tmp_path: Path, devices: str, head: str = HEAD) -> list[str]:
    with pytest.raises(LoadError) as caught:
        load(tmp_path, devices, head)
    return [str(problem) for problem in caught.value.problems]


def test_the_example_configs_load():
    for name in ("hbs2", "sim"):
        config = load_robot_config(ROOT / "examples" / "robots" / f"{name}.yaml")
        assert [d.chip for d in config.with_role("range")] == ["vl53l0x"] * 3
        assert config.device("force").pads[0].key == "/sensors/force/left_n"
        assert config.device("ultrasound").address == 0x75
        assert config.device("servos").joints[0].name == "neck"


def test_defaults_come_from_the_chip(tmp_path):
    config = load(tmp_path, "touch: {chip: mpr121}\nrange: {chip: vl53l0x, side: left}\n")

    touch = config.device("touch")
    assert (touch.bus, touch.address, touch.rate_hz) == ("i2c", 0x5A, 20.0)
    assert touch.keys == {
        "pads": "/sensors/touch/pads",
        "any": "/sensors/touch/any",
        "touched": "/sensors/touch/touched",
        "pat": "/sensors/touch/pat",
    }
    assert touch.options == {"touch_threshold": 12, "release_threshold": 6}
    assert config.device("range").keys == {"range": "/sensors/range/left_mm"}


def test_an_unknown_chip_is_named_with_its_place_and_the_nearest_chip(tmp_path):
    assert problems(tmp_path, "touch: {chip: mpr12, address: 0x5A}\n") == [
        "robot.yaml:6:17: unknown chip 'mpr12' (did you mean 'mpr121'?)"
    ]


def test_an_unknown_field_suggests_the_nearest(tmp_path):
    assert problems(tmp_path, "touch: {chip: mpr121, adress: 0x5A}\n") == [
        "robot.yaml:6:25: unknown mpr121 field 'adress' (did you mean 'address'?)"
    ]


def test_two_devices_on_one_address_of_one_bus_name_both(tmp_path):
    found = problems(
        tmp_path,
        """\
        temperature: {chip: mcp9808, address: 0x18}
        spare: {chip: tca9548a, address: 0x70}
        mux2: {chip: tca9548a, address: 0x70}
        """,
    )
    assert found == [
        "robot.yaml:8:35: I2C 0x70 on bus 'i2c' is used by both 'spare' (line 7) and 'mux2' "
        "(give each device its own address)"
    ]


def test_the_srf02_at_0x70_beside_a_pca9685_is_the_all_call_trap(tmp_path):
    found = problems(
        tmp_path,
        """\
        ultrasound: {chip: srf02}
        face: {chip: pca9685, leds: {face: {red: 0, green: 1, blue: 2}}}
        """,
    )
    assert len(found) == 1
    assert found[0].startswith("robot.yaml:6:3: 'ultrasound' at 0x70 shares its bus with PCA9685")
    assert "LED All Call" in found[0] and "e.g. 0x75" in found[0]


def test_a_pca9685_cannot_sit_on_its_all_call_address(tmp_path):
    found = problems(
        tmp_path, "face: {chip: pca9685, address: 0x70, leds: {f: {red: 0, green: 1, blue: 2}}}\n"
    )
    assert len(found) == 1
    assert found[0].startswith("robot.yaml:6:34: pca9685 cannot be at address 0x70 (0x70 is")


def test_an_address_the_chip_cannot_have_lists_the_ones_it_can(tmp_path):
    assert problems(tmp_path, "touch: {chip: mpr121, address: 0x48}\n") == [
        "robot.yaml:6:34: mpr121 cannot be at address 0x48 (use 0x5A..0x5D)"
    ]


def test_inverted_joint_limits_are_refused(tmp_path):
    found = problems(
        tmp_path,
        """\
        servos:
          chip: maestro
          joints:
            neck: {channel: 0, min_deg: 60, max_deg: -60, max_speed_dps: 90}
        """,
    )
    assert found == [
        "robot.yaml:9:35: joint 'neck': limits inverted, min_deg 60 is not below max_deg -60 "
        "(swap them)"
    ]


def test_a_joint_on_a_channel_the_maestro_lacks_is_refused(tmp_path):
    found = problems(
        tmp_path,
        """\
        servos:
          chip: maestro
          channels: 6
          joints:
            neck: {channel: 7, min_deg: -60, max_deg: 60, max_speed_dps: 90}
        """,
    )
    assert found == [
        "robot.yaml:10:23: joint 'neck': channel 7 is beyond the Maestro's 6 channels (0..5)"
    ]


def test_a_calibration_table_that_does_not_increase_points_at_the_point(tmp_path):
    found = problems(
        tmp_path,
        """\
        force:
          chip: ads1115
          pads:
            left:
              channel: 0
              calibration: [[0.0, 0.0], [2.0, 1.0], [1.5, 3.0]]
        """,
    )
    assert found == [
        "robot.yaml:11:47: calibration is not increasing: point 3 has 1.5 V after 2 V "
        "(list the points by strictly increasing volts)"
    ]


def test_a_calibration_whose_force_falls_is_refused(tmp_path):
    found = problems(
        tmp_path,
        """\
        force:
          chip: ads1115
          pads:
            left: {channel: 0, calibration: [[0.0, 0.0], [2.0, 5.0], [3.0, 4.0]]}
        """,
    )
    assert len(found) == 1
    assert found[0].startswith("robot.yaml:9:64: calibration is not increasing: point 3 has 4 N")


def test_two_pads_on_one_channel_are_refused(tmp_path):
    found = problems(
        tmp_path,
        """\
        force:
          chip: ads1115
          pads:
            left: {channel: 0, calibration: [[0.0, 0.0], [3.0, 6.0]]}
            right: {channel: 0, calibration: [[0.0, 0.0], [3.0, 6.0]]}
        """,
    )
    assert found == [
        "robot.yaml:10:14: pad 'right' uses channel 0, already used by pad 'left' "
        "(give each pad its own channel)"
    ]


def test_an_unknown_blackboard_key_suggests_the_nearest(tmp_path):
    found = problems(tmp_path, "touch: {chip: mpr121, keys: {any: /sensors/touch/anny}}\n")
    assert found == [
        "robot.yaml:6:37: 'any' unknown blackboard key '/sensors/touch/anny' "
        "(did you mean '/sensors/touch/any'?)"
    ]


def test_a_sensor_read_on_request_takes_no_poll_rate(tmp_path):
    found = problems(tmp_path, "temperature: {chip: mcp9808, rate_hz: 5}\n")
    assert found == [
        "robot.yaml:6:32: mcp9808 is not polled (temperature is read on request or commanded) "
        "(remove 'rate_hz')"
    ]


def test_a_chip_on_the_wrong_kind_of_bus_is_refused(tmp_path):
    found = problems(tmp_path, "touch: {chip: mpr121, bus: servos}\n")
    assert found == [
        "robot.yaml:6:30: mpr121 is on I2C, but bus 'servos' is serial (name a bus of kind i2c)"
    ]


def test_three_range_sensors_without_xshut_lines_cannot_share_a_bus(tmp_path):
    found = problems(
        tmp_path,
        """\
        range_left: {chip: vl53l0x, side: left}
        range_right: {chip: vl53l0x, side: right}
        """,
    )
    assert found == [
        "robot.yaml:7:3: 2 VL53L0X share bus 'i2c' but 'range_left', 'range_right' has no "
        "XSHUT line; every chip boots at 0x29 (give each its own XSHUT line, or put them "
        "behind a TCA9548A)",
        "robot.yaml:7:3: I2C 0x29 on bus 'i2c' is used by both 'range_left' (line 6) and "
        "'range_right' (give each device its own address)",
    ]


def test_only_the_last_chip_of_an_xshut_chain_may_stay_at_0x29(tmp_path):
    found = problems(
        tmp_path,
        """\
        range_left: {chip: vl53l0x, side: left, xshut: 17}
        range_right: {chip: vl53l0x, side: right, address: 0x30, xshut: 27}
        """,
    )
    assert found == [
        "robot.yaml:6:3: VL53L0X 'range_left' stays at 0x29, where the chips switched on after "
        "it boot (give it another address, or list it last)"
    ]


def test_range_sensors_behind_a_mux_may_all_keep_0x29(tmp_path):
    config = load(
        tmp_path,
        """\
        mux: {chip: tca9548a, address: 0x71}
        range_left: {chip: vl53l0x, side: left, mux: mux, channel: 0}
        range_right: {chip: vl53l0x, side: right, mux: mux, channel: 1}
        """,
    )
    assert [d.mux_channel for d in config.with_role("range")] == [0, 1]


def test_a_mux_that_is_not_there_is_named(tmp_path):
    found = problems(
        tmp_path,
        """\
        mux: {chip: tca9548a, address: 0x71}
        range_left: {chip: vl53l0x, side: left, mux: mx, channel: 0}
        """,
    )
    assert found == [
        "robot.yaml:7:48: 'mx' is not a tca9548a device of this config (did you mean 'mux'?)"
    ]


def test_gesture_names_map_the_chip_s_names_to_the_trees(tmp_path):
    config = load(tmp_path, "gesture: {chip: zx_gesture, gesture_names: {swipe_left: wave}}\n")
    assert config.device("gesture").gesture_names["swipe_left"] == "wave"
    assert config.device("gesture").gesture_names["swipe_right"] == "swipe_right"

    found = problems(tmp_path, "gesture: {chip: zx_gesture, gesture_names: {swipe_left: wav}}\n")
    assert len(found) == 1 and found[0].endswith("(did you mean 'wave'?)")


def test_every_problem_is_reported_at_once(tmp_path):
    found = problems(
        tmp_path,
        """\
        touch: {chip: mpr121, address: 0x48}
        range: {chip: vl53l0x}
        leds: {chip: pca9685}
        """,
    )
    assert [line.split(": ", 1)[0] for line in found] == [
        "robot.yaml:6:34",
        "robot.yaml:7:3",
        "robot.yaml:8:3",
    ]


def test_a_config_without_devices_or_buses_says_what_it_needs(tmp_path):
    found = problems(tmp_path, "", head="name: empty\n")
    assert found == [
        "robot.yaml:1:1: a robot config needs 'buses:' (e.g. i2c: {kind: i2c, number: 1})",
        "robot.yaml:1:1: a robot config needs 'devices:' (e.g. touch: {chip: mpr121})",
    ]


def test_one_address_behind_two_muxes_of_one_bus_is_refused(tmp_path):
    found = problems(
        tmp_path,
        """\
        muxa: {chip: tca9548a, address: 0x71}
        muxb: {chip: tca9548a, address: 0x72}
        range_left: {chip: vl53l0x, side: left, mux: muxa, channel: 0}
        range_right: {chip: vl53l0x, side: right, mux: muxb, channel: 0}
        """,
    )
    assert found == [
        "robot.yaml:9:3: I2C 0x29 is behind mux 'muxb' and, as 'range_left' (line 8), behind "
        "mux 'muxa' on the same bus 'i2c': each mux keeps its channel selected, so both chips "
        "would answer at once (put both behind 'muxa' on different channels, or give one "
        "another address)"
    ]


@pytest.mark.parametrize("bad", [".nan", ".inf", "-.inf"])
def test_a_calibration_point_that_is_not_a_finite_number_is_refused(tmp_path, bad):
    found = problems(
        tmp_path,
        f"""\
        force:
          chip: ads1115
          pads:
            left: {{channel: 0, calibration: [[0.0, 0.0], [{bad}, 1.0], [3.0, 6.0]]}}
        """,
    )
    assert len(found) == 1
    assert found[0].startswith("robot.yaml:9:52: calibration point 2 is [")
    assert found[0].endswith(
        "volts and newtons must be finite numbers (pairs of [volts, newtons], e.g. "
        "[[0.0, 0.0], [0.83, 0.2], [3.0, 6.0]])"
    )


def test_two_bus_entries_for_one_adapter_are_refused(tmp_path):
    head = """\
name: test
buses:
  front: {kind: i2c, number: 1}
  back: {kind: i2c, number: 1}
  spi: {kind: spi, number: 0}
  spi_too: {kind: spi, number: 0, chip_select: 0}
  spi_other: {kind: spi, number: 0, chip_select: 1}
  servos: {kind: serial, port: /dev/ttyACM0}
  servos_too: {kind: serial, port: /dev/ttyACM0}
devices:
"""
    found = problems(tmp_path, "touch: {chip: mpr121, bus: front}\n", head=head)
    assert found == [
        "robot.yaml:4:9: bus 'back' is /dev/i2c-1, like bus 'front' (line 3): one adapter "
        "needs one bus entry, or two owners would use it at once (remove 'back' and put its "
        "devices on bus 'front')",
        "robot.yaml:6:12: bus 'spi_too' is /dev/spidev0.0, like bus 'spi' (line 5): one "
        "adapter needs one bus entry, or two owners would use it at once (remove 'spi_too' "
        "and put its devices on bus 'spi')",
        "robot.yaml:9:15: bus 'servos_too' is /dev/ttyACM0, like bus 'servos' (line 8): one "
        "adapter needs one bus entry, or two owners would use it at once (remove "
        "'servos_too' and put its devices on bus 'servos')",
    ]


@pytest.mark.parametrize(("field", "value"), [("min_us", "0.1"), ("max_us", "4500")])
def test_a_pulse_limit_the_maestro_cannot_send_is_refused_saying_its_range(tmp_path, field, value):
    limits = {"min_us": "1000", "max_us": "2000", field: value}
    found = problems(
        tmp_path,
        f"""\
        servos:
          chip: maestro
          joints:
            neck: {{channel: 0, min_deg: -60, max_deg: 60, max_speed_dps: 90,
                    min_us: {limits["min_us"]}, max_us: {limits["max_us"]}}}
        """,
    )
    assert len(found) == 1
    assert found[0].startswith("robot.yaml:10:")
    expected = f"joint 'neck': {field} {value} us is outside the Maestro's pulse range 64..4000 us"
    assert expected in found[0]


@pytest.mark.parametrize("name", ["to/uch", "face leds", "5"])
def test_a_device_name_that_is_not_an_identifier_is_refused(tmp_path, name):
    found = problems(tmp_path, f'"{name}": {{chip: mpr121}}\n')
    assert len(found) == 1
    assert found[0].startswith(
        f"robot.yaml:6:3: device name {name!r} is not an identifier: use letters, digits and _"
    )
    assert "/devices/<name>/ok" in found[0]


def test_readings_mapped_onto_keys_of_another_type_are_refused(tmp_path):
    # touch's pads (a list) and any (a bool) swapped: touch would never fire
    found = problems(
        tmp_path,
        "touch:\n  chip: mpr121\n  keys: {pads: /sensors/touch/any, any: /sensors/touch/pads}\n",
    )
    assert found == [
        "robot.yaml:8:18: reading 'pads' is a list, but /sensors/touch/any holds a bool "
        "(map it to /sensors/touch/pads or to a /vars/ key)",
        "robot.yaml:8:43: reading 'any' is a bool, but /sensors/touch/pads holds a list "
        "(map it to /sensors/touch/any or to a /vars/ key)",
    ]


def test_a_reading_may_go_to_a_variable_of_any_type(tmp_path):
    config = load(tmp_path, "touch: {chip: mpr121, keys: {any: /vars/touched}}\n")
    assert config.devices["touch"].keys["any"] == "/vars/touched"


def test_a_release_threshold_above_the_touch_threshold_is_refused(tmp_path):
    found = problems(
        tmp_path, "touch: {chip: mpr121, touch_threshold: 10, release_threshold: 20}\n"
    )
    assert found == [
        "robot.yaml:6:65: MPR121 release threshold 20 is above the touch threshold 10; release "
        "must be at most touch (hysteresis) (release_threshold <= touch_threshold)"
    ]


def test_an_srf02_above_0x77_is_refused_with_its_range(tmp_path):
    found = problems(tmp_path, "far: {chip: srf02, address: 0x78}\n")
    assert found == ["robot.yaml:6:31: srf02 cannot be at address 0x78 (use 0x70..0x77)"]


def test_a_vl53l0x_timeout_shorter_than_one_measurement_is_refused(tmp_path):
    found = problems(tmp_path, "range_center: {chip: vl53l0x, side: center, timeout_s: 0.02}\n")
    assert found == ["robot.yaml:6:58: 'timeout_s' must be at least 0.05, got 0.02"]
