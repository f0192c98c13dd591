"""The Maestro driver against the emulated Maestro, through a real pseudo-terminal.

Serial replies cross the pty asynchronously, so a test never sleeps: it waits by reading
with the port's timeout. A command without a reply is followed by a query before the clock
is advanced; the reply proves the emulator has seen the command.
"""

from __future__ import annotations

import errno
import os
import pty
import tty
from collections.abc import Iterator
from pathlib import Path

import pytest
import serial

from engine.clock import VirtualClock
from engine.drivers.bus_manager import BusManager
from engine.drivers.maestro import Maestro, describe_port_error
from engine.drivers.maestro_protocol import (
    decode_errors,
    decode_u16,
    encode_get_errors,
    encode_get_moving_state,
    encode_get_position,
    encode_go_home,
    encode_pololu,
    encode_set_acceleration,
    encode_set_speed,
    encode_set_target,
    us_to_quarter_us,
)
from engine.drivers.servo_joints import Joint, ServoJoints
from engine.errors import DeviceError
from engine.sim.maestro_emulator import MaestroEmulator


@pytest.fixture
def emulator(clock: VirtualClock) -> Iterator[MaestroEmulator]:
    with MaestroEmulator(clock, limits_us=(500.0, 2500.0)) as emulator:
        yield emulator


@pytest.fixture
def port(emulator: MaestroEmulator) -> Iterator[serial.Serial]:
    with serial.Serial(emulator.port_name, baudrate=115200, timeout=0.5) as port:
        yield port


@pytest.fixture
def maestro(port: serial.Serial, clock: VirtualClock) -> Iterator[Maestro]:
    with Maestro(port, clock=clock) as maestro:
        yield maestro


# --- the bytes on the wire, without a port -----------------------------------------------


def test_set_target_matches_the_users_guide_example() -> None:
    # Channel 2 to 1500 us = 6000 quarter-us, 7 bits per data byte, low bits first.
    assert encode_set_target(2, us_to_quarter_us(1500)) == bytes([0x84, 0x02, 0x70, 0x2E])


def test_set_speed_matches_the_users_guide_example() -> None:
    assert encode_set_speed(5, 140) == bytes([0x87, 0x05, 0x0C, 0x01])


def test_the_other_commands_are_their_command_bytes() -> None:
    assert encode_set_acceleration(3, 4) == bytes([0x89, 0x03, 0x04, 0x00])
    assert encode_get_position(11) == bytes([0x90, 0x0B])
    assert encode_get_moving_state() == b"\x93"
    assert encode_get_errors() == b"\xa1"
    assert encode_go_home() == b"\xa2"


def test_pololu_protocol_prefixes_device_number_and_clears_the_command_msb() -> None:
    packet = encode_pololu(12, encode_set_target(0, 6000))
    assert packet == bytes([0xAA, 0x0C, 0x04, 0x00, 0x70, 0x2E])


def test_values_that_do_not_fit_14_bits_are_refused_not_wrapped() -> None:
    with pytest.raises(ValueError, match="16384"):
        encode_set_target(0, 16384)
    with pytest.raises(ValueError, match="256"):
        encode_set_acceleration(0, 256)
    with pytest.raises(ValueError, match="5000"):
        us_to_quarter_us(5000)


def test_replies_are_little_endian() -> None:
    assert decode_u16(bytes([0x70, 0x17])) == 6000
    with pytest.raises(ValueError, match="2-byte"):
        decode_u16(b"\x70")


def test_error_register_decodes_into_named_bits() -> None:
    assert decode_errors(0x0000) == []
    assert decode_errors(0x0111) == [
        "serial signal error",
        "serial protocol error",
        "script program counter error",
    ]
    assert decode_errors(0x0200) == ["unknown error bit 9"]


def test_permission_problems_say_what_to_do() -> None:
    assert "dialout" in describe_port_error(errno.EACCES)
    assert "no such file" in describe_port_error(errno.ENOENT)


# --- moving servos ----------------------------------------------------------------------


def test_a_target_without_limits_takes_effect_at_once(maestro: Maestro) -> None:
    maestro.set_target_us(0, 1500)
    assert maestro.get_position_us(0) == 1500.0
    assert not maestro.is_moving()


def test_position_moves_at_the_set_speed_as_time_passes(
    maestro: Maestro, emulator: MaestroEmulator, clock: VirtualClock
) -> None:
    maestro.set_target_us(0, 1500)
    maestro.set_speed(0, 40)  # 40 quarter-us per 10 ms = 1 us/ms
    maestro.set_target_us(0, 2000)
    # Nothing has moved yet: time stands still.
    assert maestro.get_position_us(0) == 1500.0
    assert maestro.is_moving()

    clock.advance(0.100)
    assert maestro.get_position_us(0) == 1600.0
    clock.advance(0.250)
    assert maestro.get_position_us(0) == 1850.0
    clock.advance(1.0)
    assert maestro.get_position_us(0) == 2000.0
    assert not maestro.is_moving()
    assert emulator.targets_us()[0] == 2000.0


def test_acceleration_ramps_the_speed_up_and_down(maestro: Maestro, clock: VirtualClock) -> None:
    maestro.set_target_us(1, 1000)
    maestro.set_acceleration(1, 4)  # 1250 us/s^2
    maestro.set_target_us(1, 2000)
    positions = []
    for _ in range(25):
        clock.advance(0.1)
        positions.append(maestro.get_position_us(1))
    steps = [after - before for before, after in zip([1000.0, *positions], positions, strict=False)]
    # Gently out of the start, fastest in the middle, gently into the target.
    assert steps[0] < 10
    assert max(steps) > 5 * steps[0]
    assert steps.index(max(steps)) in range(6, 11)
    assert all(step >= 0 for step in steps)
    assert positions[-1] == 2000.0
    assert not maestro.is_moving()


def test_wait_until_stopped_lets_the_clock_run_until_the_servo_arrives(
    maestro: Maestro, clock: VirtualClock
) -> None:
    maestro.set_target_us(2, 1000)
    maestro.set_speed(2, 20)  # 0.5 us/ms: 500 us takes one second
    maestro.set_target_us(2, 1500)
    maestro.wait_until_stopped(timeout_s=5.0)
    assert maestro.get_position_us(2) == 1500.0
    assert clock.now() == pytest.approx(1.0, abs=0.03)


def test_wait_until_stopped_gives_up_after_its_timeout(maestro: Maestro) -> None:
    maestro.set_target_us(2, 1000)
    maestro.set_speed(2, 1)  # the slowest: 25 us/s
    maestro.set_target_us(2, 2000)
    with pytest.raises(DeviceError, match=r"still moving after 0\.5 s"):
        maestro.wait_until_stopped(timeout_s=0.5)


def test_go_home_turns_servos_off_by_default(maestro: Maestro) -> None:
    maestro.set_target_us(0, 1500)
    maestro.go_home()
    assert maestro.get_position_us(0) == 0.0


def test_go_home_eases_to_the_configured_home(clock: VirtualClock) -> None:
    with (
        MaestroEmulator(clock, home={0: 1500.0, 1: "ignore"}) as emulator,
        serial.Serial(emulator.port_name, timeout=0.5) as port,
        Maestro(port, clock=clock) as maestro,
    ):
        assert maestro.get_position_us(0) == 1500.0  # a home position is where it starts
        maestro.set_target_us(0, 1800)
        maestro.set_target_us(1, 1200)
        maestro.set_speed(0, 40)
        maestro.go_home()
        assert maestro.get_position_us(0) == 1800.0
        clock.advance(0.2)
        assert maestro.get_position_us(0) == 1600.0
        assert maestro.get_position_us(1) == 1200.0  # "ignore" keeps its target
        assert emulator.targets_us()[:2] == [1500.0, 1200.0]


def test_targets_beyond_the_channel_limits_stop_at_the_limit(clock: VirtualClock) -> None:
    # A new Maestro allows 992..2000 us on every channel and clamps silently.
    with (
        MaestroEmulator(clock) as emulator,
        serial.Serial(emulator.port_name, timeout=0.5) as port,
        Maestro(port, clock=clock) as maestro,
    ):
        maestro.set_target_us(0, 2400)
        assert maestro.get_position_us(0) == 2000.0


def test_the_driver_refuses_channels_a_mini_maestro_12_lacks(maestro: Maestro) -> None:
    with pytest.raises(ValueError, match=r"channel 12 is outside 0\.\.11"):
        maestro.set_target_us(12, 1500)


# --- errors -----------------------------------------------------------------------------


def test_an_interrupted_command_is_a_protocol_error_and_sends_servos_home(
    maestro: Maestro, port: serial.Serial
) -> None:
    maestro.set_target_us(0, 1500)
    port.write(bytes([0x84, 0x00]))  # Set Target cut short by ...
    port.write(bytes([0xA1]))  # ... Get Errors, which then runs and reports it
    assert decode_errors(decode_u16(port.read(2))) == ["serial protocol error"]
    assert maestro.get_position_us(0) == 0.0  # home is "off"
    assert maestro.get_errors() == []  # reading cleared the register


def test_an_unknown_command_byte_is_a_protocol_error(maestro: Maestro, port: serial.Serial) -> None:
    port.write(bytes([0xB5]))
    assert maestro.get_errors() == ["serial protocol error"]


def test_a_stray_data_byte_is_a_protocol_error(maestro: Maestro, port: serial.Serial) -> None:
    port.write(bytes([0x42]))
    assert maestro.get_errors() == ["serial protocol error"]


def test_a_channel_the_maestro_lacks_is_a_protocol_error(
    maestro: Maestro, port: serial.Serial
) -> None:
    port.write(encode_set_target(12, 6000))
    assert maestro.get_errors() == ["serial protocol error"]


def test_serial_timeout_sends_servos_home(clock: VirtualClock) -> None:
    with (
        MaestroEmulator(clock, home={0: 1500.0}, serial_timeout_s=1.0) as emulator,
        serial.Serial(emulator.port_name, timeout=0.5) as port,
        Maestro(port, clock=clock) as maestro,
    ):
        maestro.set_target_us(0, 1800)
        clock.advance(0.9)
        assert maestro.get_position_us(0) == 1800.0  # the query kept the link alive
        clock.advance(0.9)
        assert maestro.get_position_us(0) == 1800.0
        clock.advance(1.2)
        assert maestro.get_errors() == ["serial timeout"]
        assert maestro.get_position_us(0) == 1500.0


def test_script_errors_are_reported_by_name(maestro: Maestro, emulator: MaestroEmulator) -> None:
    emulator.inject_error("script stack error")
    emulator.inject_error("serial overrun error")
    assert maestro.get_errors() == ["serial overrun error", "script stack error"]


# --- the Pololu protocol and device numbers ---------------------------------------------


def test_pololu_protocol_reaches_the_maestro_with_its_device_number(
    port: serial.Serial, clock: VirtualClock
) -> None:
    maestro = Maestro(port, device=12, protocol="pololu", clock=clock)
    maestro.set_target_us(3, 1750)
    assert maestro.get_position_us(3) == 1750.0
    assert maestro.get_errors() == []


def test_commands_for_another_device_number_are_ignored(
    maestro: Maestro, port: serial.Serial, emulator: MaestroEmulator
) -> None:
    maestro.set_target_us(3, 1500)
    port.write(encode_pololu(13, encode_set_target(3, 8000)))
    assert maestro.get_position_us(3) == 1500.0
    assert maestro.get_errors() == []  # not ours is not malformed
    assert emulator.targets_us()[3] == 1500.0


def test_a_maestro_that_never_answers_times_out_naming_the_port(
    port: serial.Serial, emulator: MaestroEmulator, clock: VirtualClock
) -> None:
    port.timeout = 0.05
    other = Maestro(port, device=13, protocol="pololu", clock=clock)
    with pytest.raises(DeviceError, match=emulator.port_name) as raised:
        other.get_position_us(0)
    assert "no reply to Get Position" in str(raised.value)
    assert raised.value.errno == errno.ETIMEDOUT


def test_a_borrowed_port_without_timeout_is_refused(
    emulator: MaestroEmulator, clock: VirtualClock
) -> None:
    with (
        serial.Serial(emulator.port_name, timeout=None) as port,
        pytest.raises(ValueError, match="timeout"),
    ):
        Maestro(port, clock=clock)


def test_device_numbers_are_7_bit(port: serial.Serial, clock: VirtualClock) -> None:
    with pytest.raises(ValueError, match="128"):
        Maestro(port, device=128, protocol="pololu", clock=clock)


# --- who owns the port ------------------------------------------------------------------


def test_a_port_opened_by_name_is_closed_by_close(
    emulator: MaestroEmulator, clock: VirtualClock
) -> None:
    maestro = Maestro(emulator.port_name, clock=clock)
    maestro.set_target_us(0, 1234)
    assert maestro.get_position_us(0) == 1234.0
    opened = maestro.port
    maestro.close()
    assert not opened.is_open  # type: ignore[attr-defined]
    with pytest.raises(DeviceError, match="closed"):
        maestro.set_target_us(0, 1500)


def test_a_borrowed_port_stays_open(port: serial.Serial, clock: VirtualClock) -> None:
    with Maestro(port, clock=clock) as maestro:
        maestro.set_target_us(0, 1500)
    assert port.is_open
    assert Maestro(port, clock=clock).get_position_us(0) == 1500.0


def test_a_port_opened_by_name_is_not_shared(
    emulator: MaestroEmulator, clock: VirtualClock
) -> None:
    with (
        Maestro(emulator.port_name, clock=clock),
        pytest.raises(DeviceError, match="busy") as raised,
    ):
        Maestro(emulator.port_name, clock=clock)
    assert emulator.port_name in str(raised.value)


def test_a_missing_port_names_the_path_and_says_no_such_file() -> None:
    with pytest.raises(DeviceError, match="/dev/ttyNOMAESTRO") as raised:
        Maestro("/dev/ttyNOMAESTRO", clock=VirtualClock())
    assert "no such file" in str(raised.value)
    assert raised.value.errno == errno.ENOENT


def test_closing_the_emulator_removes_its_port(clock: VirtualClock) -> None:
    emulator = MaestroEmulator(clock)
    name = emulator.port_name
    assert os.path.exists(name)
    emulator.close()
    assert not os.path.exists(name)


def test_a_maestro_opened_by_name_carries_on_after_its_cable_was_pulled_and_plugged_back(
    tmp_path: Path, clock: VirtualClock
) -> None:
    link = tmp_path / "ttyACM0"  # the port's name, as udev gives it
    first = MaestroEmulator(clock)
    link.symlink_to(first.port_name)
    maestro = Maestro(str(link), clock=clock, timeout_s=0.5)
    manager = BusManager(maestro, name=str(link), clock=clock, kind="serial", threaded=False)
    servos = manager.claim("servos")
    second: MaestroEmulator | None = None
    try:
        servos.call(lambda m: m.set_target_us(0, 1500))
        assert servos.call(lambda m: m.get_position_us(0)) == 1500.0

        first.close()  # the cable is pulled: the port goes away
        link.unlink()
        with pytest.raises(DeviceError, match="opened again at the next command"):
            servos.call(lambda m: m.set_target_us(0, 1600))
        with pytest.raises(DeviceError, match="no such file"):
            servos.call(lambda m: m.set_target_us(0, 1600))

        second = MaestroEmulator(clock)  # plugged back in, under the same name
        link.symlink_to(second.port_name)
        servos.call(lambda m: m.set_target_us(0, 1600))

        assert servos.call(lambda m: m.get_position_us(0)) == 1600.0
        assert second.targets_us()[0] == 1600.0
    finally:
        manager.close()
        maestro.close()
        first.close()
        if second is not None:
            second.close()


def test_a_maestro_not_plugged_in_at_start_up_is_opened_by_the_first_command_after_it_appears(
    tmp_path: Path, clock: VirtualClock
) -> None:
    link = tmp_path / "ttyACM0"
    maestro = Maestro(str(link), clock=clock, timeout_s=0.5, connect=False)  # nothing there
    emulator: MaestroEmulator | None = None
    try:
        with pytest.raises(DeviceError, match="no such file"):
            maestro.set_target_us(0, 1500)
        emulator = MaestroEmulator(clock)  # plugged in later
        link.symlink_to(emulator.port_name)
        maestro.set_target_us(0, 1500)
        assert maestro.get_position_us(0) == 1500.0
    finally:
        maestro.close()
        if emulator is not None:
            emulator.close()


# --- a Maestro that never answers ---------------------------------------------------------


@pytest.fixture
def silent_port() -> Iterator[serial.Serial]:
    """A serial port that takes every byte and never answers: a pseudo-terminal whose other
    end nobody serves (a Maestro without power behind its USB adapter, a wrong port)."""
    controller, terminal = pty.openpty()
    tty.setraw(terminal)
    try:
        with serial.Serial(os.ttyname(terminal), timeout=0.05) as port:
            yield port
    finally:
        os.close(terminal)
        os.close(controller)


def test_a_silent_maestro_takes_commands_but_its_queries_time_out_naming_the_port(
    silent_port: serial.Serial, clock: VirtualClock
) -> None:
    maestro = Maestro(silent_port, clock=clock)
    maestro.set_target_us(0, 1500)  # a command has no reply: nothing to notice yet
    with pytest.raises(DeviceError, match="no reply to Get Position") as raised:
        maestro.get_position_us(0)
    assert silent_port.name in str(raised.value)
    assert raised.value.errno == errno.ETIMEDOUT
    with pytest.raises(DeviceError, match="no reply to Get Errors"):
        maestro.get_errors()


def test_moves_to_a_silent_maestro_fail_and_it_goes_offline(
    silent_port: serial.Serial, clock: VirtualClock
) -> None:
    maestro = Maestro(silent_port, clock=clock)
    statuses: list[tuple[str, bool]] = []
    manager = BusManager(
        maestro,
        name=silent_port.name,
        clock=clock,
        kind="serial",
        threaded=False,
        on_status=lambda device, ok: statuses.append((device, ok)),
    )
    servos = manager.claim("servos")
    joints = ServoJoints(maestro, [Joint("neck_pan", 0, -60.0, 60.0, 120.0)], clock=clock)

    for angle_deg in (10.0, 20.0, 30.0):
        with pytest.raises(DeviceError, match="no reply to Get Position"):
            servos.call(lambda _: joints.move("neck_pan", angle_deg))  # noqa: B023

    assert not servos.online
    assert statuses == [("servos", True), ("servos", False)]
    assert servos.stats().errors == 3
