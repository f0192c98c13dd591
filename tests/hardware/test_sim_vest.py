"""The paper's interactions end to end on the simulated vest, without the CLI.

The world moves the simulated chips; the drivers read them at register level through the
bus managers; the pollers stage the readings; the trees answer through the services,
which drive the simulated PCA9685 and the Maestro emulator (over a real pseudo-terminal).
Time is virtual; nothing sleeps. The Maestro's replies are read with serial timeouts.
"""

from __future__ import annotations

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import VirtualClock
from engine.drivers import zx_gesture_registers
from engine.drivers.servo_joints import angle_to_us
from engine.files.problems import Mark
from engine.hardware.assembly import build_hardware
from engine.hardware.config import RobotConfig
from engine.hardware.config_file import load_robot_config
from engine.hardware.fault_events import check_fault_events
from engine.hardware.sim_vest import build_sim_vest
from engine.scenario.scenario_file import ScenarioEvent
from engine.scenario.world import World

from .conftest import MUXED, ROOT, SimRobot

PINK = (0.8, 0.1, 0.3)  # pink dimmed to sim.yaml's safety max_brightness 0.8


def face_duty(robot: SimRobot, led: str = "left_eye") -> tuple[float, float, float]:
    """The duty cycles the simulated PCA9685 outputs on one LED's red, green, blue."""
    pca = robot.vest.chips["face_leds"]
    red, green, blue = robot.hardware.config.device("face_leds").leds[led]
    return (pca.duty(red), pca.duty(green), pca.duty(blue))


def test_squeezing_both_sides_says_i_love_hugs_and_lights_the_face_pink(sim_robot: SimRobot):
    sim_robot.run_for(0.5)
    assert face_duty(sim_robot) == (0.0, 0.0, 0.0)

    sim_robot.squeeze(left_n=6.0, right_n=6.0)
    sim_robot.run_for(0.2)

    assert sim_robot.said == ["I love hugs!"]
    assert sim_robot.key("/sensors/force/left_n") == pytest.approx(6.0, abs=0.05)
    for duty, wanted in zip(face_duty(sim_robot), PINK, strict=True):
        assert duty == pytest.approx(wanted, abs=0.01)  # pink, in 1/4096 steps
    assert face_duty(sim_robot, "right_eye") == face_duty(sim_robot)

    sim_robot.squeeze(0.0, 0.0)
    sim_robot.run_for(2.0)  # SetLed lasts 2 s
    assert face_duty(sim_robot) == (0.0, 0.0, 0.0)
    assert sim_robot.said == ["I love hugs!"]


def test_a_light_squeeze_on_one_side_is_no_hug(sim_robot: SimRobot):
    sim_robot.squeeze(left_n=6.0, right_n=1.0)
    sim_robot.run_for(0.5)

    assert sim_robot.key("/sensors/force/right_n") == pytest.approx(1.0, abs=0.05)
    assert sim_robot.said == []


def test_touching_pad_3_says_thank_you(sim_robot: SimRobot):
    sim_robot.touch(3)
    sim_robot.run_for(0.2)

    assert sim_robot.said == ["Thank you"]
    pads = sim_robot.key("/sensors/touch/pads")
    assert [pad for pad, touched in enumerate(pads) if touched] == [3]


def test_an_obstacle_on_the_left_turns_the_neck_on_the_maestro(sim_robot: SimRobot):
    neck = sim_robot.hardware.config.device("servos").joints[0]
    channel = neck.channel
    sim_robot.run_for(0.3)
    assert sim_robot.hardware.servos.position_deg("neck") == pytest.approx(0.0)  # home

    sim_robot.obstacle(left=250.0, center=600.0, right=900.0)
    sim_robot.run_for(0.3)

    assert sim_robot.key("/sensors/range/left_mm") == 250.0
    assert sim_robot.key("/sensors/range/right_mm") == 900.0
    # A query answered over the pty proves the emulator has taken the target before it.
    sim_robot.hardware.servos.position_deg("neck")
    assert sim_robot.vest.maestro.targets_us()[channel] == angle_to_us(neck, 30.0)
    sim_robot.run_for(1.0)  # 30 deg at 90 deg/s
    assert sim_robot.hardware.servos.position_deg("neck") == pytest.approx(30.0, abs=0.5)


def test_nothing_in_range_reads_as_none(sim_robot: SimRobot):
    sim_robot.obstacle(left=2000.0)  # beyond the VL53L0X's reach
    sim_robot.run_for(0.3)

    assert sim_robot.key("/sensors/range/left_mm") is None
    assert sim_robot.key("/sensors/range/center_mm") is None


def test_asking_the_temperature_reads_the_mcp9808(sim_robot: SimRobot):
    sim_robot.room_at(22.2)
    sim_robot.run_for(0.5)  # the chip converts every 250 ms at 1/16 degC resolution
    sim_robot.hear("what is the temperature")
    sim_robot.run_for(0.3)

    assert sim_robot.said == ["The temperature is 72 degrees"]
    # The MCP9808 reads in 1/16 degC steps: the answer came through the chip.
    assert sim_robot.key("/sensors/temperature/c") == 22.1875
    assert sim_robot.hardware.stats()["temperature"].transactions >= 1


def test_a_wave_in_front_of_the_gesture_sensor_says_hello(sim_robot: SimRobot):
    sim_robot.world.happened("gesture", "wave")
    sim_robot.run_for(0.3)

    assert sim_robot.said == ["Hello"]
    log = sim_robot.blackboard.event_log("/sensors/gesture/last")
    assert [event.value for event in log.events] == ["swipe_right"]  # what the chip saw


def test_unplugging_the_touch_sensor_marks_it_offline_and_the_rest_carry_on(
    sim_robot: SimRobot,
):
    sim_robot.run_for(0.5)
    assert sim_robot.key("/devices/touch/ok") is True
    sim_robot.touch(3)
    sim_robot.run_for(0.1)
    assert sim_robot.said == ["Thank you"]

    sim_robot.world.happened("unplug", {"device": "touch", "seconds": 3.0})
    sim_robot.run_for(0.5)

    assert sim_robot.key("/devices/touch/ok") is False
    assert sim_robot.key("/sensors/touch/any") is False  # no stale touch keeps firing
    sim_robot.squeeze(6.0, 6.0)
    sim_robot.run_for(0.2)
    assert sim_robot.said == ["Thank you", "I love hugs!"]
    assert sim_robot.key("/devices/force/ok") is True

    sim_robot.touch(3, down=False)
    sim_robot.run_for(5.0)  # the unplug ends after 3 s; the next re-probe finds the chip

    assert sim_robot.key("/devices/touch/ok") is True
    sim_robot.touch(5)
    sim_robot.run_for(0.2)
    assert sim_robot.said[-1] == "Thank you"
    stats = sim_robot.hardware.stats()["touch"]
    assert stats.online and stats.errors >= 3 and stats.refused > 0


def test_a_chip_holding_the_bus_stops_every_i2c_device_until_it_lets_go(sim_robot: SimRobot):
    sim_robot.run_for(0.2)
    sim_robot.vest.fault("gesture", "hold", 0.5)
    sim_robot.run_for(0.5)

    i2c_devices = [d.name for d in sim_robot.hardware.config if d.bus == "i2c" and d.polled]
    assert all(sim_robot.key(f"/devices/{name}/ok") is False for name in i2c_devices)
    assert sim_robot.key("/devices/servos/ok") is True  # the Maestro is on its own port

    sim_robot.run_for(3.0)
    assert all(sim_robot.key(f"/devices/{name}/ok") is True for name in i2c_devices)
    sim_robot.touch(1)
    sim_robot.run_for(0.2)
    assert sim_robot.said == ["Thank you"]


def test_an_object_ahead_is_read_on_request_after_the_srf02_ranging_time(sim_robot: SimRobot):
    sim_robot.object_ahead(120.0)
    job = sim_robot.services.sensors.read("ultrasound")

    sim_robot.clock.advance(0.050)
    assert not job.done()  # still ranging (66 ms)
    sim_robot.clock.advance(0.020)
    assert job.done()
    assert job.error() is None
    assert job.result() == {"/sensors/ultrasound/cm": 120.0}


def test_the_same_devices_are_in_the_simulation_as_on_the_robot(sim_config: RobotConfig):
    robot = load_robot_config(ROOT / "examples" / "robots" / "hbs2.yaml")
    assert not robot.simulated and sim_config.simulated
    assert [(d.name, d.chip, d.address) for d in robot] == [
        (d.name, d.chip, d.address) for d in sim_config
    ]


def test_three_range_sensors_at_0x29_behind_a_multiplexer_each_see_their_side(tmp_path):
    path = tmp_path / "muxed.yaml"
    path.write_text(MUXED)
    config = load_robot_config(path)
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    world = World(range_mm={"left": 250.0, "center": 600.0, "right": None})
    vest = build_sim_vest(config, world, clock)
    hardware = build_hardware(config, clock, board, vest=vest)
    try:
        for poller in hardware.pollers:
            poller(clock.now())
        board.commit()

        assert hardware.startup_problems == {}
        assert board.get("/sensors/range/left_mm") == 250.0
        assert board.get("/sensors/range/center_mm") == 600.0
        assert board.get("/sensors/range/right_mm") is None
        assert "via mux ch3" in repr(hardware.handles["range_center"])
    finally:
        hardware.close()
        vest.close()


def test_the_range_sensors_stop_ranging_when_the_robot_stops(sim_config: RobotConfig):
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    vest = build_sim_vest(sim_config, World(range_mm={"left": 250.0}), clock)
    hardware = build_hardware(sim_config, clock, board, vest=vest)
    chips = [vest.chips[p.name] for p in hardware.pollers if p.name.startswith("range")]
    try:
        for poller in hardware.pollers:
            poller(clock.now())
        assert chips and all(chip.ranging_back_to_back for chip in chips)
    finally:
        hardware.close()
        vest.close()

    assert not any(chip.ranging_back_to_back for chip in chips)


def test_fault_events_must_name_a_device_the_simulation_can_fail(sim_config: RobotConfig):
    here = Mark("demo.yaml", 4, 5)
    events = [
        ScenarioEvent(1.0, "unplug", {"device": "touch", "seconds": 3.0}, here),
        ScenarioEvent(2.0, "unplug", {"device": "tuch", "seconds": 3.0}, here),
        ScenarioEvent(3.0, "fault", {"device": "servos", "kind": "nack", "seconds": 1.0}, here),
    ]

    problems = [str(problem) for problem in check_fault_events(events, sim_config)]

    assert problems == [
        f"demo.yaml:4:5: no device 'tuch' in {sim_config.path} (did you mean 'touch'?)",
        "demo.yaml:4:5: 'servos' (maestro) cannot be failed in the simulation "
        "(the simulated vest fails I2C and SPI devices)",
    ]


def test_a_wave_at_the_unplugged_gesture_sensor_greets_nobody_later(sim_robot: SimRobot):
    sim_robot.run_for(0.5)
    sim_robot.vest.unplug("gesture", 3.0)
    sim_robot.run_for(0.5)

    sim_robot.world.happened("gesture", "wave")  # the chip has no power: it sees nothing
    sim_robot.run_for(5.0)

    assert sim_robot.key("/devices/gesture/ok") is True  # plugged back in
    assert sim_robot.said == []
    assert not sim_robot.blackboard.event_log("/sensors/gesture/last").events
    sim_robot.world.happened("gesture", "wave")
    sim_robot.run_for(0.3)
    assert sim_robot.said == ["Hello"]


def test_an_unplugged_gesture_sensor_latches_no_gesture_for_later(sim_config: RobotConfig):
    clock = VirtualClock()
    world = World()
    vest = build_sim_vest(sim_config, world, clock)
    try:
        vest.unplug("gesture", 1.0)
        world.happened("gesture", "wave")
        clock.advance(1.5)  # plugged back in

        status = vest.i2c["i2c"].read_byte_data(0x10, zx_gesture_registers.STATUS)

        assert status & zx_gesture_registers.STATUS_GESTURES == 0
    finally:
        vest.close()
