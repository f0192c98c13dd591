"""Pololu Maestro servo controller (Mini Maestro 12) over its serial command port.

Over USB the Maestro shows up as two serial ports; commands go to the first one, the
"Command Port" (usually ``/dev/ttyACM0``), where the baud rate does not matter. The same
commands work on the TTL serial line.

The bytes of each command and reply are built and read by the pure functions of
:mod:`engine.drivers.maestro_protocol`; :class:`Maestro` only moves them over the port,
and notices a Maestro that does not answer: every query has the port's read timeout, and
one that times out raises a :class:`~engine.errors.DeviceError` naming the port.
"""

from __future__ import annotations

import contextlib
import errno
import termios
import threading
from types import TracebackType
from typing import Literal, Self

import serial

from engine.clock import Clock
from engine.drivers.bus_protocols import SerialPort
from engine.drivers.device_errors import errno_in_words
from engine.drivers.maestro_protocol import (
    DEFAULT_DEVICE_NUMBER,
    MAX_DEVICE_NUMBER,
    QUARTER_US_PER_US,
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
from engine.errors import DeviceError

_PORT_ADVICE = {
    errno.ENOENT: "no such file: is the Maestro plugged in? (its command port is often "
    "/dev/ttyACM0)",
    errno.EACCES: "permission denied: add yourself to the dialout group",
    errno.EPERM: "permission denied: add yourself to the dialout group",
    errno.EBUSY: "busy: another program has it open",
    errno.EAGAIN: "busy: another program has it open",
    errno.ENXIO: "no such device: was the Maestro unplugged?",
    errno.ENODEV: "no such device: was the Maestro unplugged?",
}


def describe_port_error(code: int | None) -> str:
    """Words for an errno from opening or using a serial port, with what to do about it."""
    return errno_in_words(code, _PORT_ADVICE)


# --- the device ----------------------------------------------------------------------------


class Maestro:
    """A Pololu Maestro on a serial port.

    ``port`` is an open pyserial-compatible port (the caller keeps ownership) or a port name
    that this class opens and, on :meth:`close`, closes. A port opened by name is also
    closed when it fails (the USB cable was pulled: every write fails from then on) and
    opened again by the next command, so a Maestro plugged back in under the same name
    carries on; until then each command fails with a :class:`DeviceError` saying why.
    ``device`` is the Pololu-protocol
    device number (0..127), used when ``protocol="pololu"``; ``channels`` is 12 for a Mini
    Maestro 12. ``clock`` paces :meth:`wait_until_stopped`. ``baudrate`` and
    ``timeout_s`` apply only when the port is opened here; a borrowed port must have a
    timeout so that a silent Maestro cannot hang a read.

    Thread-safe: each command and its reply form one transaction.
    """

    def __init__(
        self,
        port: SerialPort | str,
        *,
        device: int = DEFAULT_DEVICE_NUMBER,
        protocol: Literal["compact", "pololu"] = "compact",
        channels: int = 12,
        clock: Clock,
        baudrate: int = 115200,
        timeout_s: float = 0.5,
        connect: bool = True,
    ) -> None:
        """``connect=False`` with a port name opens the port at the first command instead
        of now (a Maestro that is not plugged in yet does not stop the robot starting)."""
        if not 0 <= device <= MAX_DEVICE_NUMBER:
            raise ValueError(f"Maestro device number {device} is outside 0..{MAX_DEVICE_NUMBER}")
        if protocol not in ("compact", "pololu"):
            raise ValueError(f"Maestro protocol {protocol!r} is neither 'compact' nor 'pololu'")
        if channels not in (6, 12, 18, 24):
            raise ValueError(f"a Maestro has 6, 12, 18 or 24 channels, not {channels}")
        self.device = device
        self.protocol = protocol
        self.channels = channels
        self._clock = clock
        self._lock = threading.Lock()
        self._closed = False
        self._baudrate = baudrate
        self._timeout_s = timeout_s
        self._port: SerialPort | None
        if isinstance(port, str):
            self._port = (
                _open_port(port, baudrate=baudrate, timeout_s=timeout_s) if connect else None
            )
            self._owns_port = True
            self._port_name = port
        else:
            if getattr(port, "timeout", None) is None:
                raise ValueError(
                    "the Maestro's serial port needs a read timeout (port.timeout is None), "
                    "or a silent Maestro would hang every read"
                )
            self._port = port
            self._owns_port = False
            self._port_name = str(getattr(port, "port", None) or getattr(port, "name", port))

    @property
    def port(self) -> SerialPort:
        """The serial port in use (owned by this object only if it was opened by name).

        Raises :class:`DeviceError` while a port opened by name is lost (the next command
        opens it again).
        """
        port = self._port
        if port is None:
            raise DeviceError(errno.ENODEV, f"Maestro on {self._port_name}: the port is not open")
        return port

    @property
    def port_name(self) -> str:
        """The port's path, for messages."""
        return self._port_name

    # -- commands ---------------------------------------------------------------------------

    def set_target_us(self, channel: int, pulse_us: float) -> None:
        """Move ``channel`` to a pulse width of ``pulse_us`` microseconds (0 turns it off).

        The Maestro clamps targets to the channel's Min/Max configured on the device and
        honours its speed and acceleration limits.
        """
        self._check_channel(channel)
        self._send(encode_set_target(channel, us_to_quarter_us(pulse_us)))

    def set_speed(self, channel: int, speed: int) -> None:
        """Limit ``channel``'s speed, in (0.25 us)/(10 ms) (0 = unlimited)."""
        self._check_channel(channel)
        self._send(encode_set_speed(channel, speed))

    def set_acceleration(self, channel: int, acceleration: int) -> None:
        """Limit ``channel``'s acceleration, in (0.25 us)/(10 ms)/(80 ms), 0..255 (0 = off)."""
        self._check_channel(channel)
        self._send(encode_set_acceleration(channel, acceleration))

    def get_position_us(self, channel: int) -> float:
        """The pulse width the Maestro sends on ``channel`` now, in us (0.0 when it is off).

        This is the commanded position after speed/acceleration limits, not a measurement:
        hobby servos report nothing back.
        """
        self._check_channel(channel)
        reply = self._query(encode_get_position(channel), 2, "Get Position")
        return decode_u16(reply) / QUARTER_US_PER_US

    def is_moving(self) -> bool:
        """Whether any speed- or acceleration-limited servo has not reached its target yet."""
        reply = self._query(encode_get_moving_state(), 1, "Get Moving State")
        return reply[0] != 0

    def get_errors(self) -> list[str]:
        """Names of the errors the Maestro has seen since the last call (reading clears them)."""
        reply = self._query(encode_get_errors(), 2, "Get Errors")
        return decode_errors(decode_u16(reply))

    def go_home(self) -> None:
        """Send every channel to the home the Maestro is configured with (default: off)."""
        self._send(encode_go_home())

    def wait_until_stopped(self, timeout_s: float, *, poll_s: float = 0.02) -> None:
        """Wait on the clock until no servo moves; DeviceError after ``timeout_s`` seconds."""
        if timeout_s < 0 or poll_s <= 0:
            raise ValueError(f"timeout_s {timeout_s} and poll_s {poll_s} must be positive")
        deadline_s = self._clock.now() + timeout_s
        while self.is_moving():
            if self._clock.now() >= deadline_s:
                raise DeviceError(
                    errno.ETIMEDOUT,
                    f"Maestro on {self._port_name}: servos still moving after {timeout_s} s",
                )
            self._clock.sleep(poll_s)

    def close(self) -> None:
        """Stop using the port; close it only if this object opened it."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            if self._owns_port and self._port is not None:
                self._port.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    # -- transport --------------------------------------------------------------------------

    def _check_channel(self, channel: int) -> None:
        if not 0 <= channel < self.channels:
            raise ValueError(
                f"channel {channel} is outside 0..{self.channels - 1} "
                f"(Maestro on {self._port_name})"
            )

    def _frame(self, packet: bytes) -> bytes:
        return encode_pololu(self.device, packet) if self.protocol == "pololu" else packet

    def _send(self, packet: bytes) -> None:
        with self._lock:
            self._write(packet)

    def _query(self, packet: bytes, reply_length: int, what: str) -> bytes:
        with self._lock:
            port = self._ready_port()
            try:
                # A reply that came too late for an earlier query must not answer this one.
                port.reset_input_buffer()
            except _PORT_ERRORS as error:
                raise self._io_error(error) from error
            self._write(packet)
            try:
                reply = port.read(reply_length)
            except _PORT_ERRORS as error:
                raise self._io_error(error) from error
        if len(reply) < reply_length:
            raise DeviceError(
                errno.ETIMEDOUT,
                f"Maestro on {self._port_name}: no reply to {what} within "
                f"{port.timeout} s (got {len(reply)} of {reply_length} bytes; "
                f"protocol {self.protocol}, device number {self.device})",
            )
        return reply

    def _check_open(self) -> None:
        if self._closed:
            raise DeviceError(errno.EBADF, f"Maestro on {self._port_name} is closed")

    def _ready_port(self) -> SerialPort:
        """The port, opened again by name if it was lost (lock held)."""
        self._check_open()
        if self._port is None:
            self._port = _open_port(
                self._port_name, baudrate=self._baudrate, timeout_s=self._timeout_s
            )
        return self._port

    def _write(self, packet: bytes) -> None:
        port = self._ready_port()
        try:
            port.write(self._frame(packet))
            port.flush()
        except _PORT_ERRORS as error:
            raise self._io_error(error) from error

    def _io_error(self, error: OSError | termios.error) -> DeviceError:
        """The port failed: words for it; a port opened by name is closed, to open again."""
        if isinstance(error, DeviceError):
            return error
        code = error.errno if isinstance(error, OSError) else _termios_errno(error)
        words = describe_port_error(code) if code else str(error)
        if self._owns_port and self._port is not None:
            lost, self._port = self._port, None
            with contextlib.suppress(*_PORT_ERRORS):  # it is gone already
                lost.close()
            words += "; the port is opened again at the next command"
        return DeviceError(code or errno.EIO, f"Maestro on {self._port_name}: {words}")


_PORT_ERRORS = (OSError, termios.error)
"""What a failing port raises: pyserial's SerialException (an OSError), or termios.error
from its flush and buffer resets."""


def _termios_errno(error: termios.error) -> int | None:
    code = error.args[0] if error.args else None
    return code if isinstance(code, int) else None


def _open_port(name: str, *, baudrate: int, timeout_s: float) -> serial.Serial:
    """Open ``name`` exclusively, turning pyserial's errors into a DeviceError in words."""
    try:
        return serial.Serial(
            port=name,
            baudrate=baudrate,
            timeout=timeout_s,
            write_timeout=timeout_s,
            exclusive=True,
        )
    except serial.SerialException as error:
        raise DeviceError(
            error.errno or errno.EIO,
            f"cannot open Maestro port {name}: {describe_port_error(error.errno)}",
        ) from error
    except ValueError as error:  # pyserial's answer to a bad baud rate or timeout
        raise DeviceError(errno.EINVAL, f"cannot open Maestro port {name}: {error}") from error
