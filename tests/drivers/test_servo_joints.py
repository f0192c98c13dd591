"""Servo joints in degrees, on the emulated Maestro through a real pseudo-terminal."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import serial

from engine.clock import VirtualClock
from engine.drivers.maestro import Maestro
from engine.drivers.servo_joints import (
    Joint,
    ServoJoints,
    angle_to_us,
    joints_from_config,
    speed_dps_to_maestro,
    us_to_angle,
)
from engine.errors import ConfigError, ServiceError
from engine.sim.maestro_emulator import MaestroEmulator

NECK = Joint("neck_pan", 0, -60.0, 60.0, 120.0, min_us=1000.0, max_us=2000.0)
ARM = Joint("arm_left", 1, 0.0, 90.0, 45.0, min_us=1100.0, max_us=1820.0, home_deg=10.0)


@pytest.fixture
def emulator(clock: VirtualClock) -> Iterator[MaestroEmulator]:
    with MaestroEmulator(clock, limits_us=(900.0, 2100.0)) as emulator:
        yield emulator


@pytest.fixture
def maestro(emulator: MaestroEmulator, clock: VirtualClock) -> Iterator[Maestro]:
    with (
        serial.Serial(emulator.port_name, baudrate=115200, timeout=0.5) as port,
        Maestro(port, clock=clock) as maestro,
    ):
        yield maestro


@pytest.fixture
def joints(maestro: Maestro, clock: VirtualClock) -> ServoJoints:
    return ServoJoints(maestro, [NECK, ARM], clock=clock)


# --- pure conversions -------------------------------------------------------------------


def test_angle_to_us_is_linear_between_the_pulse_limits() -> None:
    assert angle_to_us(NECK, -60.0) == 1000.0
    assert angle_to_us(NECK, 0.0) == 1500.0
    assert angle_to_us(NECK, 60.0) == 2000.0
    assert angle_to_us(ARM, 45.0) == 1460.0
    assert us_to_angle(ARM, 1460.0) == 45.0


def test_speed_in_degrees_per_second_becomes_maestro_units_rounded_down() -> None:
    # Neck: 1000 us over 120 deg; 120 deg/s = 1000 us/s = 40 x (0.25 us / 10 ms).
    assert speed_dps_to_maestro(NECK, 120.0) == 40
    # Arm: 8 us/deg; 45 deg/s = 360 us/s = 14.4 units, so 14, never 15.
    assert speed_dps_to_maestro(ARM, 45.0) == 14


def test_a_speed_too_slow_to_express_is_refused_not_sent_as_unlimited() -> None:
    with pytest.raises(ValueError, match=r"neck_pan.*0\.5 deg/s.*slowest"):
        speed_dps_to_maestro(NECK, 0.5)


def test_joint_limits_must_make_sense() -> None:
    with pytest.raises(ValueError, match="min_deg 10 is not below max_deg 10"):
        Joint("wrist", 2, 10, 10, 30)
    with pytest.raises(ValueError, match=r"home_deg 0\.0 is outside 10\.\.80 deg"):
        Joint("wrist", 2, 10, 80, 30)


def test_joints_come_from_the_robot_config() -> None:
    section = {
        "neck_pan": {"channel": 0, "min_deg": -60, "max_deg": 60, "max_speed_dps": 120},
        "arm_left": {
            "channel": 1,
            "min_deg": 0,
            "max_deg": 90,
            "max_speed_dps": 45,
            "min_us": 1100,
            "max_us": 1820,
            "home_deg": 10,
        },
    }
    neck, arm = joints_from_config(section)
    assert neck == Joint("neck_pan", 0, -60, 60, 120)
    assert arm == ARM


def test_a_config_mistake_names_the_joint_and_setting() -> None:
    typo = {"neck_pan": {"channel": 0, "min_deg": -60, "max_deg": 60, "max_dps": 9}}
    with pytest.raises(ConfigError, match=r"servos\.neck_pan: unknown setting\(s\) \['max_dps'\]"):
        joints_from_config(typo)
    with pytest.raises(ConfigError, match=r"servos\.neck_pan: .*max_speed_dps"):
        joints_from_config({"neck_pan": {"channel": 0, "min_deg": -60, "max_deg": 60}})


# --- moving joints ----------------------------------------------------------------------


def test_a_joint_reaches_its_angle_at_the_asked_speed(
    joints: ServoJoints, clock: VirtualClock
) -> None:
    joints.home()  # from "off", the Maestro jumps to the first target
    assert joints.position_deg("neck_pan") == 0.0
    assert joints.position_deg("arm_left") == 10.0

    joints.move("neck_pan", 30.0, speed_dps=60.0)
    assert joints.is_moving()
    clock.advance(0.25)
    assert joints.position_deg("neck_pan") == pytest.approx(15.0)
    clock.advance(0.25)
    assert joints.position_deg("neck_pan") == pytest.approx(30.0)
    assert not joints.is_moving()


def test_a_move_without_speed_goes_at_the_joints_limit(
    joints: ServoJoints, clock: VirtualClock
) -> None:
    joints.home()
    joints.move("arm_left", 90.0)
    joints.wait_until_still(timeout_s=5.0)
    assert joints.position_deg("arm_left") == pytest.approx(90.0)
    # 80 deg at 14 units (350 us/s = 43.75 deg/s, just under the 45 deg/s limit).
    assert clock.now() == pytest.approx(80 / 43.75, abs=0.03)


def test_an_angle_beyond_the_limit_is_refused_and_nothing_is_sent(
    joints: ServoJoints, emulator: MaestroEmulator
) -> None:
    joints.home()
    before = emulator.targets_us()
    with pytest.raises(ValueError, match=r"'neck_pan': angle 75 deg .* -60.0..60.0 deg"):
        joints.move("neck_pan", 75)
    with pytest.raises(ValueError, match=r"'arm_left': angle -1 deg .* 0.0..90.0 deg"):
        joints.move("arm_left", -1)
    assert emulator.targets_us() == before


def test_a_speed_beyond_the_limit_is_refused(
    joints: ServoJoints, emulator: MaestroEmulator
) -> None:
    joints.home()
    before = emulator.targets_us()
    with pytest.raises(ValueError, match=r"'arm_left': speed 50 deg/s .* <= 45.0 deg/s"):
        joints.move("arm_left", 30, speed_dps=50)
    with pytest.raises(ValueError, match=r"'arm_left': speed 0 deg/s"):
        joints.move("arm_left", 30, speed_dps=0)
    assert emulator.targets_us() == before


def test_an_unknown_joint_lists_the_known_ones(joints: ServoJoints) -> None:
    known = "unknown joint 'neck_tilt'; known joints: neck_pan, arm_left"
    with pytest.raises(ValueError, match=known):
        joints.move("neck_tilt", 0)


def test_an_unpowered_joint_has_no_known_angle(joints: ServoJoints) -> None:
    with pytest.raises(ServiceError, match=r"'neck_pan' \(channel 0\) is off"):
        joints.position_deg("neck_pan")


def test_two_joints_cannot_share_a_channel(maestro: Maestro, clock: VirtualClock) -> None:
    tilt = Joint("neck_tilt", 0, -30, 30, 60)
    with pytest.raises(ValueError, match="channel 0 is already used by 'neck_pan'"):
        ServoJoints(maestro, [NECK, tilt], clock=clock)


def test_a_joint_on_a_channel_the_maestro_lacks_is_refused(
    maestro: Maestro, clock: VirtualClock
) -> None:
    leg = Joint("leg", 17, -30, 30, 60)
    with pytest.raises(ValueError, match=r"channel 17 is outside the controller's 0..11"):
        ServoJoints(maestro, [leg], clock=clock)


def test_a_pulse_too_short_to_tell_from_off_is_refused_and_the_servo_stays_driven(
    maestro: Maestro, clock: VirtualClock
) -> None:
    tiny = Joint("neck_pan", 0, -60.0, 60.0, 120.0, min_us=0.1, max_us=2000.0)
    joints = ServoJoints(maestro, [tiny], clock=clock)
    joints.move("neck_pan", 0.0)
    assert maestro.get_position_us(0) == 1000.0

    with pytest.raises(ValueError, match=r"'neck_pan': angle -60.0 deg is a pulse of 0.1 us"):
        joints.move("neck_pan", -60.0)

    assert maestro.get_position_us(0) == 1000.0  # not switched off
