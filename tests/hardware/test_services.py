"""Services on the drivers: LEDs, servo joints with limits, sensors read on request."""

from __future__ import annotations

import pytest

from engine.errors import DeviceError, ServiceError
from engine.sim.pca9685 import SimPCA9685

from .conftest import SimRobot


def blue_duty(robot: SimRobot) -> float:
    pca = robot.vest.chips["face_leds"]
    _, _, blue = robot.hardware.config.device("face_leds").leds["left_eye"]
    return pca.duty(blue)


def test_leds_light_and_go_dark_when_their_seconds_are_up(sim_robot: SimRobot):
    leds = sim_robot.hardware.leds
    assert leds is not None
    job = leds.set_color("blue", seconds=1.0)

    assert not job.done()  # lit for a second
    sim_robot.clock.advance(0.5)
    assert blue_duty(sim_robot) == 1.0
    sim_robot.clock.advance(0.5)
    assert job.done() and job.error() is None
    leds(sim_robot.clock.now())  # the scheduler hook

    assert blue_duty(sim_robot) == 0.0
    assert leds.color == "off"


def test_a_color_until_changed_stays(sim_robot: SimRobot):
    leds = sim_robot.hardware.leds
    assert leds is not None
    assert leds.set_color("#0000FF").done()

    sim_robot.run_for(5.0)

    assert blue_duty(sim_robot) == 1.0


def test_an_unknown_color_fails_the_job_and_lights_nothing(sim_robot: SimRobot):
    leds = sim_robot.hardware.leds
    assert leds is not None
    before = sim_robot.hardware.stats()["face_leds"].transactions

    job = leds.set_color("ultraviolet")

    assert job.done() and isinstance(job.error(), ServiceError)
    assert "unknown color 'ultraviolet'" in str(job.error())
    assert sim_robot.hardware.stats()["face_leds"].transactions == before


def test_a_move_beyond_a_joint_s_limits_fails_with_the_reason_and_sends_nothing(
    sim_robot: SimRobot,
):
    servos = sim_robot.hardware.servos
    assert servos is not None
    before = sim_robot.hardware.stats()["servos"].transactions

    job = servos.move("neck", 75.0)

    assert job.done()
    assert str(job.error()) == "joint 'neck': angle 75 deg is outside its limits -60..60 deg"
    assert sim_robot.hardware.stats()["servos"].transactions == before
    assert servos.position_deg("neck") == pytest.approx(0.0)


def test_an_unknown_joint_and_a_speed_above_the_limit_are_refused(sim_robot: SimRobot):
    servos = sim_robot.hardware.servos
    assert servos is not None

    assert "known joints: neck, left_arm, right_arm" in str(servos.move("tail", 10.0).error())
    assert "outside its limit 0 < speed <= 120" in str(
        servos.move("neck", 10.0, speed_dps=500.0).error()
    )


def test_a_move_lasts_as_long_as_the_joint_takes_at_its_speed(sim_robot: SimRobot):
    servos = sim_robot.hardware.servos
    assert servos is not None

    job = servos.move("left_arm", 30.0, speed_dps=60.0)
    # The reply to a query proves the emulator took the move before time moves on.
    assert servos.position_deg("left_arm") == pytest.approx(0.0, abs=0.5)

    sim_robot.clock.advance(0.45)
    assert not job.done()
    sim_robot.clock.advance(0.05)
    assert job.done() and job.error() is None
    assert servos.position_deg("left_arm") == pytest.approx(30.0, abs=0.5)


def test_a_temperature_below_freezing_reads_below_zero(sim_robot: SimRobot):
    sim_robot.room_at(-5.5)
    sim_robot.run_for(0.5)

    job = sim_robot.services.sensors.read("temperature")

    assert job.done()
    assert job.result() == {"/sensors/temperature/c": -5.5, "/sensors/temperature/f": 22.1}


def test_a_temperature_sensor_that_does_not_answer_fails_with_the_errno_in_words(
    sim_robot: SimRobot,
):
    sim_robot.vest.unplug("temperature", 1.0)

    job = sim_robot.services.sensors.read("temperature")

    assert job.done() and isinstance(job.error(), DeviceError)
    assert "Remote I/O error" in str(job.error())


def test_nothing_ahead_of_the_srf02_reads_as_none(sim_robot: SimRobot):
    job = sim_robot.services.sensors.read("ultrasound")

    sim_robot.clock.advance(0.07)

    assert job.done() and job.result() == {"/sensors/ultrasound/cm": None}


def test_two_requests_during_one_ranging_share_it(sim_robot: SimRobot):
    sim_robot.object_ahead(80.0)
    first = sim_robot.services.sensors.read("ultrasound")
    sim_robot.clock.advance(0.03)
    second = sim_robot.services.sensors.read("ultrasound")

    sim_robot.clock.advance(0.04)

    assert first.done() and second.done()
    assert first.result() == second.result() == {"/sensors/ultrasound/cm": 80.0}
    assert sim_robot.hardware.stats()["ultrasound"].transactions <= 4  # start, result, (init)


def test_an_unknown_sensor_names_the_known_ones(sim_robot: SimRobot):
    job = sim_robot.services.sensors.read("humidity")

    assert str(job.error()) == "no sensor 'humidity' (known: temperature, ultrasound)"


def test_leds_whose_time_ran_out_while_unplugged_go_dark_once_the_chip_is_back(
    sim_robot: SimRobot,
):
    leds = sim_robot.hardware.leds
    assert leds is not None
    leds.set_color("blue", seconds=1.0)
    sim_robot.vest.unplug("face_leds", 2.0)

    sim_robot.run_for(1.5)  # the "off" at 1 s cannot reach the chip
    assert blue_duty(sim_robot) == 1.0

    sim_robot.run_for(1.5)  # back at 2 s

    assert blue_duty(sim_robot) == 0.0
    assert leds.color == "off"


def test_a_new_face_board_shows_the_color_the_face_should_show(sim_robot: SimRobot):
    leds = sim_robot.hardware.leds
    assert leds is not None
    assert leds.set_color("blue").done()
    bus = sim_robot.vest.i2c["i2c"]

    bus.detach(0x40)  # the face board is pulled...
    with pytest.raises(DeviceError):
        leds.read_now()
    board = SimPCA9685(sim_robot.vest.clock, 0x40)  # ...and a new one, dark, plugged in
    bus.attach(board)
    leds.read_now()

    _, _, blue = sim_robot.hardware.config.device("face_leds").leds["left_eye"]
    assert board.duty(blue) == 1.0
