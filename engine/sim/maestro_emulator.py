"""A simulated Pololu Mini Maestro behind a real pseudo-terminal.

The emulator opens a pty pair and serves the Maestro's serial protocol on the master side,
so the driver talks to :attr:`MaestroEmulator.port_name` through pyserial exactly as it
talks to ``/dev/ttyACM0`` on the robot. It models the controller as the user's guide
describes it (sections 4 and 5):

* every 10 ms (the default 20 ms servo period) each channel's position steps toward its
  target, by at most its speed limit in (0.25 us)/(10 ms), its speed changing by at most
  its acceleration limit in (0.25 us)/(10 ms)/(80 ms) and ramping down before the target;
  0 means unlimited for both. Time is the injected clock's, evaluated when someone asks;
* targets are clamped to the channel's Min/Max (default 992..2000 us); a target of 0 turns
  the channel off (position 0), and an off channel jumps straight to its next target;
* the compact, Pololu (0xAA, device number) and Mini SSC (0xFF) protocols are all
  accepted at once; Pololu packets for another device number are skipped;
* a malformed packet (unknown command byte, a data byte without a command, a packet
  interrupted by a new command byte, a channel the Maestro lacks) sets the serial
  protocol error bit; with a serial timeout configured, silence sets the timeout bit.
  Any error sends every channel home, as the real one does; Get Errors reads and clears.

Not modelled: the script (its commands are accepted and do nothing), CRC mode, PWM output,
input and digital-output channels, servo periods other than 20 ms. Over USB the real
command port has no baud rate, framing or overrun to get wrong, so signal, overrun and
buffer-full errors only arise through :meth:`MaestroEmulator.inject_error`.
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import select
import threading
import tty
from collections.abc import Mapping
from types import TracebackType
from typing import Literal, Self

from engine.clock import Clock
from engine.drivers.maestro_protocol import (
    CMD_GET_ERRORS,
    CMD_GET_MOVING_STATE,
    CMD_GET_POSITION,
    CMD_GET_SCRIPT_STATUS,
    CMD_GO_HOME,
    CMD_SET_ACCELERATION,
    CMD_SET_MULTIPLE_TARGETS,
    CMD_SET_SPEED,
    CMD_SET_TARGET,
    COMMAND_DATA_LENGTHS,
    ERROR_NAMES,
    ERROR_SERIAL_PROTOCOL,
    ERROR_SERIAL_TIMEOUT,
    MAX_ACCELERATION,
    MAX_DEVICE_NUMBER,
    MINI_SSC_START,
    POLOLU_PROTOCOL_START,
    QUARTER_US_PER_US,
)
from engine.sim.servo_channel import ServoChannel

TICK_S = 0.010
"""The Maestro updates servo positions every 10 ms (at the default 20 ms period)."""

DEFAULT_LIMITS_US = (992.0, 2000.0)
"""A new Maestro's Min and Max for every channel."""
EIGHT_BIT_NEUTRAL_US = 1500.0
EIGHT_BIT_RANGE_US = 476.25

HomeSetting = float | Literal["off", "ignore"]
"""A channel's "on startup or error" setting: a pulse width in us, "off" or "ignore"."""


def _ticks(time_s: float) -> int:
    # The epsilon keeps 0.1 s from landing on tick 9.999... after float arithmetic.
    return math.floor(time_s / TICK_S + 1e-9)


def _data(value_low: int, value_high: int) -> int:
    return value_low | (value_high << 7)


class MaestroEmulator:
    """A Mini Maestro serving its serial protocol on a pseudo-terminal.

    ``channels`` and ``device`` (the Pololu-protocol device number) are the controller's;
    ``limits_us`` is each channel's (Min, Max) in us, one pair for all or a mapping by
    channel; ``home`` is the "on startup or error" setting by channel (default "off");
    ``serial_timeout_s`` enables the serial timeout (None: disabled, as shipped).
    """

    def __init__(
        self,
        clock: Clock,
        *,
        channels: int = 12,
        device: int = 12,
        limits_us: tuple[float, float] | Mapping[int, tuple[float, float]] = DEFAULT_LIMITS_US,
        home: Mapping[int, HomeSetting] | None = None,
        serial_timeout_s: float | None = None,
    ) -> None:
        if channels not in (6, 12, 18, 24):
            raise ValueError(f"a Maestro has 6, 12, 18 or 24 channels, not {channels}")
        if not 0 <= device <= MAX_DEVICE_NUMBER:
            raise ValueError(f"Maestro device number {device} is outside 0..{MAX_DEVICE_NUMBER}")
        if serial_timeout_s is not None and serial_timeout_s <= 0:
            raise ValueError(f"serial_timeout_s {serial_timeout_s} must be positive or None")
        self._clock = clock
        self.device = device
        self._serial_timeout_s = serial_timeout_s
        self._channels = [
            self._make_channel(channel, limits_us, (home or {}).get(channel, "off"))
            for channel in range(channels)
        ]
        self._errors = 0
        self._tick = _ticks(clock.now())
        self._last_valid_s = clock.now()
        self._timed_out = False
        self._state: Literal["idle", "device", "pololu_command", "skip", "data", "mini_ssc"]
        self._state = "idle"
        self._command = 0
        self._packet = bytearray()
        self._lock = threading.Lock()
        self._closed = False

        self._master_fd, self._slave_fd = os.openpty()
        tty.setraw(self._slave_fd)
        os.set_blocking(self._master_fd, False)
        self.port_name = os.ttyname(self._slave_fd)
        self._wake_r, self._wake_w = os.pipe()
        self._thread = threading.Thread(
            target=self._serve, name=f"maestro-emulator {self.port_name}", daemon=True
        )
        self._thread.start()

    @staticmethod
    def _make_channel(
        channel: int,
        limits_us: tuple[float, float] | Mapping[int, tuple[float, float]],
        home: HomeSetting,
    ) -> ServoChannel:
        if isinstance(limits_us, Mapping):
            low_us, high_us = limits_us.get(channel, DEFAULT_LIMITS_US)
        else:
            low_us, high_us = limits_us
        if not 0 < low_us < high_us <= 4095.75:
            raise ValueError(f"channel {channel} limits {low_us}..{high_us} us are not ordered")
        low, high = round(low_us * QUARTER_US_PER_US), round(high_us * QUARTER_US_PER_US)
        if home in ("off", "ignore"):
            return ServoChannel(low, high, home)
        if isinstance(home, str) or not low_us <= home <= high_us:
            raise ValueError(
                f"channel {channel} home {home!r} is neither 'off', 'ignore' nor a pulse "
                f"width within {low_us}..{high_us} us"
            )
        home_qus = round(home * QUARTER_US_PER_US)
        # At startup a servo with a home position starts there, without easing in.
        return ServoChannel(low, high, home_qus, target=home_qus, position=float(home_qus))

    # -- what tests look at -----------------------------------------------------------------

    def targets_us(self) -> list[float]:
        """Every channel's target in us (0.0: off), as of the clock's now."""
        with self._lock:
            self._advance_to(self._clock.now())
            return [channel.target / QUARTER_US_PER_US for channel in self._channels]

    def inject_error(self, name: str) -> None:
        """Raise one of the Maestro's errors by name (see ``ERROR_NAMES``), as if it occurred."""
        masks = {error_name: mask for mask, error_name in ERROR_NAMES.items()}
        if name not in masks:
            raise ValueError(f"unknown Maestro error {name!r}; known: {', '.join(masks)}")
        with self._lock:
            self._advance_to(self._clock.now())
            self._raise_error(masks[name])

    # -- life cycle -------------------------------------------------------------------------

    def close(self) -> None:
        """Stop serving and close both ends of the pty (the port name disappears)."""
        if self._closed:
            return
        self._closed = True
        os.write(self._wake_w, b"x")
        self._thread.join()
        for fd in (self._master_fd, self._slave_fd, self._wake_r, self._wake_w):
            os.close(fd)

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def _serve(self) -> None:
        while not self._closed:
            readable, _, _ = select.select([self._master_fd, self._wake_r], [], [], 0.05)
            if self._closed or self._wake_r in readable:
                return
            if self._master_fd not in readable:
                continue
            try:
                received = os.read(self._master_fd, 4096)
            except BlockingIOError:
                continue
            except OSError as error:  # EIO: no slave end left open
                if error.errno == errno.EIO:
                    return
                raise
            with self._lock:
                now_s = self._clock.now()
                self._advance_to(now_s)
                reply = bytearray()
                for byte in received:
                    reply += self._receive(byte, now_s)
            # If the host stopped reading and its buffer is full, replies are lost.
            if reply:
                with contextlib.suppress(BlockingIOError):
                    os.write(self._master_fd, reply)

    # -- servo model ------------------------------------------------------------------------

    def _advance_to(self, now_s: float) -> None:
        tick = _ticks(now_s)
        if self._serial_timeout_s is not None and not self._timed_out:
            timeout_tick = _ticks(self._last_valid_s + self._serial_timeout_s)
            if timeout_tick <= tick:
                self._step(timeout_tick)
                self._timed_out = True
                self._raise_error(ERROR_SERIAL_TIMEOUT)
        self._step(tick)

    def _step(self, tick: int) -> None:
        if tick > self._tick:
            for channel in self._channels:
                channel.step(tick - self._tick)
            self._tick = tick

    def _raise_error(self, mask: int) -> None:
        self._errors |= mask
        for channel in self._channels:
            channel.go_home()

    # -- protocol ---------------------------------------------------------------------------

    def _receive(self, byte: int, now_s: float) -> bytes:
        """Feed one received byte; returns the reply it completes, if any."""
        if self._state == "mini_ssc":
            if byte == MINI_SSC_START:  # a new Mini SSC packet cut this one short
                self._raise_error(ERROR_SERIAL_PROTOCOL)
                self._packet.clear()
                return b""
            self._packet.append(byte)
            if len(self._packet) == 2:
                self._state = "idle"
                self._mini_ssc(self._packet[0], self._packet[1], now_s)
            return b""
        if byte & 0x80:
            if self._state in ("device", "pololu_command", "data"):
                self._raise_error(ERROR_SERIAL_PROTOCOL)  # an unfinished packet interrupted
            self._state = "idle"
            self._packet.clear()
            if byte == POLOLU_PROTOCOL_START:
                self._state = "device"
                return b""
            if byte == MINI_SSC_START:
                self._state = "mini_ssc"
                return b""
            return self._start(byte, now_s)
        if self._state == "idle":
            self._raise_error(ERROR_SERIAL_PROTOCOL)  # a data byte with no command
            return b""
        if self._state == "skip":
            return b""  # a packet for another device on the line
        if self._state == "device":
            self._state = "pololu_command" if byte == self.device else "skip"
            return b""
        if self._state == "pololu_command":
            return self._start(byte | 0x80, now_s)
        self._packet.append(byte)
        return self._execute_if_complete(now_s)

    def _start(self, command: int, now_s: float) -> bytes:
        if command not in COMMAND_DATA_LENGTHS:
            self._state = "idle"
            self._raise_error(ERROR_SERIAL_PROTOCOL)
            return b""
        self._state = "data"
        self._command = command
        self._packet.clear()
        return self._execute_if_complete(now_s)

    def _execute_if_complete(self, now_s: float) -> bytes:
        needed = COMMAND_DATA_LENGTHS[self._command]
        if self._command == CMD_SET_MULTIPLE_TARGETS and self._packet:
            needed = 2 + 2 * self._packet[0]
        if len(self._packet) < needed:
            return b""
        self._state = "idle"
        reply = self._execute(self._command, bytes(self._packet))
        if reply is None:  # refused: not a valid command, so the serial timeout runs on
            return b""
        self._last_valid_s = now_s
        self._timed_out = False
        return reply

    def _channel(self, number: int) -> ServoChannel | None:
        if number < len(self._channels):
            return self._channels[number]
        self._raise_error(ERROR_SERIAL_PROTOCOL)
        return None

    def _execute(self, command: int, data: bytes) -> bytes | None:
        """Carry out a complete packet; its reply, or None if it was refused."""
        if command in (CMD_SET_TARGET, CMD_SET_SPEED, CMD_SET_ACCELERATION):
            channel = self._channel(data[0])
            if channel is None:
                return None
            value = _data(data[1], data[2])
            if command == CMD_SET_TARGET:
                channel.set_target(value)
            elif command == CMD_SET_SPEED:
                channel.speed = value
            else:
                channel.acceleration = min(value, MAX_ACCELERATION)
        elif command == CMD_SET_MULTIPLE_TARGETS:
            count, first = data[0], data[1]
            if first + count > len(self._channels):
                self._raise_error(ERROR_SERIAL_PROTOCOL)
                return None
            for index in range(count):
                low, high = data[2 + 2 * index], data[3 + 2 * index]
                self._channels[first + index].set_target(_data(low, high))
        elif command == CMD_GET_POSITION:
            channel = self._channel(data[0])
            if channel is None:
                return None
            return round(channel.position).to_bytes(2, "little")
        elif command == CMD_GET_MOVING_STATE:
            return bytes((int(any(channel.moving for channel in self._channels)),))
        elif command == CMD_GET_ERRORS:
            errors, self._errors = self._errors, 0
            return errors.to_bytes(2, "little")
        elif command == CMD_GO_HOME:
            for channel in self._channels:
                channel.go_home()
        elif command == CMD_GET_SCRIPT_STATUS:
            return b"\x01"  # no script is running
        return b""

    def _mini_ssc(self, servo: int, value: int, now_s: float) -> None:
        # Servo numbers beyond this Maestro's channels belong to the next one on the line.
        if servo >= len(self._channels):
            return
        self._last_valid_s = now_s
        self._timed_out = False
        pulse_us = EIGHT_BIT_NEUTRAL_US + (value - 127) * EIGHT_BIT_RANGE_US / 127
        self._channels[servo].set_target(round(pulse_us * QUARTER_US_PER_US))
