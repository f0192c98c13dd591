"""`vest devices` rows: every configured device, its identity, one reading."""

from __future__ import annotations

from engine.hardware.device_report import describe_devices, format_rows

from .conftest import SimRobot


def test_every_device_of_the_simulated_vest_answers_with_one_reading(sim_robot: SimRobot):
    sim_robot.squeeze(left_n=2.0, right_n=0.0)
    sim_robot.obstacle(left=300.0)

    rows = {row.name: row for row in describe_devices(sim_robot.hardware)}

    assert list(rows) == list(sim_robot.hardware.config.devices)
    assert all(row.ok for row in rows.values())
    assert rows["touch"].where == "I2C 0x5A on /dev/i2c-1"
    assert rows["touch"].identity == "answers as mpr121"
    assert rows["force"].reading == "left 2.0 N, right 0.0 N"
    assert rows["range_left"].reading == "300 mm"
    assert rows["range_center"].reading == "nothing in range"
    assert rows["servos"].identity == "answers as a Maestro; errors: none"
    assert rows["servos"].reading.startswith("neck 0 deg")


def test_a_device_that_does_not_answer_says_why(sim_robot: SimRobot):
    sim_robot.vest.unplug("range_right", 5.0)

    rows = {row.name: row for row in describe_devices(sim_robot.hardware)}

    assert not rows["range_right"].ok
    assert rows["range_right"].identity.startswith("no: range_right (I2C 0x32 on bus 1): Remote")
    assert rows["range_right"].reading == "-"
    assert rows["range_left"].ok


def test_the_rows_print_as_an_aligned_table(sim_robot: SimRobot):
    text = format_rows(describe_devices(sim_robot.hardware))

    lines = text.splitlines()
    assert lines[0].split() == ["device", "chip", "where", "identity", "reading"]
    assert lines[1].startswith("touch ") and "mpr121" in lines[1]
    assert len(lines) == 1 + len(sim_robot.hardware.config.devices)
