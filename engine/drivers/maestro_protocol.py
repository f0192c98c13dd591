"""The Pololu Maestro's serial protocol as pure functions: bytes out, values back.

The protocol (Maestro user's guide, sections 5.c and 5.e) is a command byte with its most
significant bit set followed by data bytes with it cleared, so every 14-bit value travels
as two 7-bit bytes, low bits first. The *compact* protocol sends the command byte itself;
the *Pololu* protocol sends ``0xAA``, the device number and the command byte with its MSB
cleared, so several Pololu controllers can share one line. Replies are plain bytes, 16-bit
values little-endian.

Pulse widths travel in quarter-microseconds (a target of 6000 is 1500 us; 0 stops the
pulses). Speed is in (0.25 us)/(10 ms), acceleration in (0.25 us)/(10 ms)/(80 ms), for the
default 20 ms servo period; 0 means unlimited for both.

Nothing here touches a port: :class:`~engine.drivers.maestro.Maestro` moves the bytes.
"""

from __future__ import annotations

# Command bytes (compact protocol).
CMD_SET_TARGET = 0x84
CMD_SET_SPEED = 0x87
CMD_SET_ACCELERATION = 0x89
CMD_GET_POSITION = 0x90
CMD_GET_MOVING_STATE = 0x93
CMD_GET_ERRORS = 0xA1
CMD_GO_HOME = 0xA2
POLOLU_PROTOCOL_START = 0xAA
"""First byte of a Pololu-protocol packet (also the baud-rate indication byte)."""

# Commands the engine does not send (the emulator reads past them).
CMD_SET_PWM = 0x8A
CMD_SET_MULTIPLE_TARGETS = 0x9F
CMD_STOP_SCRIPT = 0xA4
CMD_RESTART_SCRIPT = 0xA7
CMD_RESTART_SCRIPT_WITH_PARAMETER = 0xA8
CMD_GET_SCRIPT_STATUS = 0xAE
MINI_SSC_START = 0xFF  # first byte of a Mini SSC packet

# Data bytes after each command byte, so that a reader of the byte stream stays in step.
COMMAND_DATA_LENGTHS: dict[int, int] = {
    CMD_SET_TARGET: 3,
    CMD_SET_SPEED: 3,
    CMD_SET_ACCELERATION: 3,
    CMD_SET_PWM: 4,
    CMD_GET_POSITION: 1,
    CMD_GET_MOVING_STATE: 0,
    CMD_SET_MULTIPLE_TARGETS: 2,  # at least; 2 + 2 * count in all
    CMD_GET_ERRORS: 0,
    CMD_GO_HOME: 0,
    CMD_STOP_SCRIPT: 0,
    CMD_RESTART_SCRIPT: 1,
    CMD_RESTART_SCRIPT_WITH_PARAMETER: 3,
    CMD_GET_SCRIPT_STATUS: 0,
}

DEFAULT_DEVICE_NUMBER = 12
MAX_DEVICE_NUMBER = 127
MAX_14_BIT = 0x3FFF
MAX_ACCELERATION = 255
QUARTER_US_PER_US = 4

# Error register (user's guide section 4.e): read and cleared by Get Errors.
ERROR_SERIAL_SIGNAL = 1 << 0
ERROR_SERIAL_OVERRUN = 1 << 1
ERROR_SERIAL_BUFFER_FULL = 1 << 2
ERROR_SERIAL_CRC = 1 << 3
ERROR_SERIAL_PROTOCOL = 1 << 4
ERROR_SERIAL_TIMEOUT = 1 << 5
ERROR_SCRIPT_STACK = 1 << 6
ERROR_SCRIPT_CALL_STACK = 1 << 7
ERROR_SCRIPT_PROGRAM_COUNTER = 1 << 8

ERROR_NAMES: dict[int, str] = {
    ERROR_SERIAL_SIGNAL: "serial signal error",
    ERROR_SERIAL_OVERRUN: "serial overrun error",
    ERROR_SERIAL_BUFFER_FULL: "serial buffer full",
    ERROR_SERIAL_CRC: "serial CRC error",
    ERROR_SERIAL_PROTOCOL: "serial protocol error",
    ERROR_SERIAL_TIMEOUT: "serial timeout",
    ERROR_SCRIPT_STACK: "script stack error",
    ERROR_SCRIPT_CALL_STACK: "script call stack error",
    ERROR_SCRIPT_PROGRAM_COUNTER: "script program counter error",
}
"""Bit mask -> name of each error the Maestro reports, in bit order."""


# --- pure encoding -------------------------------------------------------------------------


def _check_data_byte(what: str, value: int) -> None:
    if not 0 <= value <= 0x7F:
        raise ValueError(f"{what} {value} does not fit a 7-bit data byte (0..127)")


def _encode_14_bit(what: str, value: int) -> bytes:
    if not 0 <= value <= MAX_14_BIT:
        raise ValueError(f"{what} {value} is outside 0..{MAX_14_BIT} (14 bits)")
    return bytes((value & 0x7F, (value >> 7) & 0x7F))


def us_to_quarter_us(pulse_us: float) -> int:
    """A pulse width in microseconds as the Maestro's integer quarter-microseconds."""
    quarter_us = round(pulse_us * QUARTER_US_PER_US)
    if not 0 <= quarter_us <= MAX_14_BIT:
        raise ValueError(
            f"pulse width {pulse_us} us is outside 0..{MAX_14_BIT / QUARTER_US_PER_US} us"
        )
    return quarter_us


def encode_set_target(channel: int, quarter_us: int) -> bytes:
    """Set Target: ``channel`` moves to ``quarter_us`` (0.25 us units; 0 stops its pulses)."""
    _check_data_byte("channel", channel)
    return bytes((CMD_SET_TARGET, channel)) + _encode_14_bit("target", quarter_us)


def encode_set_speed(channel: int, speed: int) -> bytes:
    """Set Speed: limit in (0.25 us)/(10 ms); 0 is unlimited."""
    _check_data_byte("channel", channel)
    return bytes((CMD_SET_SPEED, channel)) + _encode_14_bit("speed", speed)


def encode_set_acceleration(channel: int, acceleration: int) -> bytes:
    """Set Acceleration: limit in (0.25 us)/(10 ms)/(80 ms), 0..255; 0 is unlimited."""
    _check_data_byte("channel", channel)
    if not 0 <= acceleration <= MAX_ACCELERATION:
        raise ValueError(f"acceleration {acceleration} is outside 0..{MAX_ACCELERATION}")
    return bytes((CMD_SET_ACCELERATION, channel)) + _encode_14_bit("acceleration", acceleration)


def encode_get_position(channel: int) -> bytes:
    """Get Position: the reply is the pulse width being sent, 2 bytes little-endian (0.25 us)."""
    _check_data_byte("channel", channel)
    return bytes((CMD_GET_POSITION, channel))


def encode_get_moving_state() -> bytes:
    """Get Moving State: the reply is 0x01 while a speed- or acceleration-limited servo moves."""
    return bytes((CMD_GET_MOVING_STATE,))


def encode_get_errors() -> bytes:
    """Get Errors: the reply is the error register, 2 bytes little-endian; reading clears it."""
    return bytes((CMD_GET_ERRORS,))


def encode_go_home() -> bytes:
    """Go Home: every channel goes to its configured home (off, unchanged, or a position)."""
    return bytes((CMD_GO_HOME,))


def encode_pololu(device: int, packet: bytes) -> bytes:
    """A compact-protocol ``packet`` rewritten for the Pololu protocol and ``device``."""
    _check_data_byte("device number", device)
    if not packet or not packet[0] & 0x80:
        raise ValueError(f"packet {packet.hex(' ')} does not start with a command byte")
    return bytes((POLOLU_PROTOCOL_START, device, packet[0] & 0x7F)) + packet[1:]


def decode_u16(reply: bytes) -> int:
    """A 2-byte little-endian reply as an integer."""
    if len(reply) != 2:
        raise ValueError(f"expected a 2-byte reply, got {reply.hex(' ') or 'nothing'}")
    return reply[0] | (reply[1] << 8)


def decode_errors(register: int) -> list[str]:
    """The error register as names, lowest bit first; unknown bits are named by number."""
    names = []
    for bit in range(16):
        mask = 1 << bit
        if register & mask:
            names.append(ERROR_NAMES.get(mask, f"unknown error bit {bit}"))
    return names
