"""TI TCA9548A 8-channel I2C multiplexer (addresses 0x70..0x77).

The chip has one register, the control byte, written and read without a register pointer:
bit n connects downstream channel n to the upstream bus. It lets several chips with the
same fixed address (three VL53L0X at 0x29) sit on one bus, one per channel.

:meth:`TCA9548A.channel_bus` returns an ``smbus2.SMBus``-compatible object for one channel:
each call selects that channel (when it is not already the selected one) and forwards,
holding the multiplexer's lock, so traffic for two channels is never interleaved.

Note: 0x70 is also the default address of the vest's SRF02 ranger; with both on one bus,
strap the TCA9548A to 0x71..0x77 (pins A0..A2).
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any, Protocol

from smbus2 import i2c_msg

from engine.errors import DeviceError

CHIP = "TCA9548A"
CHANNELS = 8
ADDRESSES = range(0x70, 0x78)


def _device_error(message: str, cause: OSError | None = None) -> DeviceError:
    """A DeviceError that keeps the errno of the bus error behind it, if it had one."""
    code = cause.errno if cause is not None else None
    return DeviceError(code, message) if isinstance(code, int) else DeviceError(message)


class SMBusLike(Protocol):
    """The part of ``smbus2.SMBus`` the multiplexer itself uses."""

    def read_byte(self, i2c_addr: int) -> int: ...

    def write_byte(self, i2c_addr: int, value: int) -> None: ...


def channel_mask(channel: int) -> int:
    """The control byte that connects ``channel`` (0..7) alone."""
    if not 0 <= channel < CHANNELS:
        raise ValueError(f"{CHIP} channel must be 0..{CHANNELS - 1}, got {channel}")
    return 1 << channel


class TCA9548A:
    """A TCA9548A on ``bus``; construction checks it answers (it has no identity register)."""

    def __init__(self, bus: Any, *, address: int = 0x70) -> None:
        if address not in ADDRESSES:
            raise ValueError(f"{CHIP} address must be 0x70..0x77, got 0x{address:02X}")
        self.bus = bus
        self.address = address
        self._lock = threading.RLock()
        try:
            self._control: int | None = bus.read_byte(address)
        except OSError as err:
            where = f"{CHIP} at 0x{address:02X}"
            raise _device_error(f"{where} did not answer: {err.strerror or err}", err) from err

    def __repr__(self) -> str:
        return f"TCA9548A(address=0x{self.address:02X})"

    @property
    def lock(self) -> threading.RLock:
        """Held while a channel is selected and used."""
        return self._lock

    def select(self, channel: int) -> None:
        """Connect ``channel`` (0..7) alone to the upstream bus."""
        self._write_control(channel_mask(channel))

    def deselect_all(self) -> None:
        """Disconnect every channel."""
        self._write_control(0x00)

    def selected(self) -> list[int]:
        """The channels connected now, as the chip reports them."""
        with self._lock:
            control = self.bus.read_byte(self.address)
            self._control = control
        return [channel for channel in range(CHANNELS) if control & (1 << channel)]

    def _write_control(self, control: int) -> None:
        with self._lock:
            self._control = None  # unknown until the write has gone through
            self.bus.write_byte(self.address, control)
            self._control = control

    def ensure_selected(self, channel: int) -> None:
        """Select ``channel`` unless it already is the only one (call holding :attr:`lock`)."""
        mask = channel_mask(channel)
        if self._control != mask:
            self._write_control(mask)

    def forget_selection(self) -> None:
        """Make the next channel access write the control byte again (after a bus error)."""
        self._control = None

    def channel_bus(self, channel: int) -> TCA9548AChannel:
        """An ``smbus2.SMBus``-compatible bus reaching the chips behind ``channel``."""
        channel_mask(channel)
        return TCA9548AChannel(self, channel)


class TCA9548AChannel:
    """One downstream channel of a :class:`TCA9548A`, with the ``smbus2.SMBus`` interface."""

    def __init__(self, mux: TCA9548A, channel: int) -> None:
        self.mux = mux
        self.channel = channel

    def __repr__(self) -> str:
        return f"{self.mux!r}.channel_bus({self.channel})"

    def _call(self, method: str, *args: Any) -> Any:
        with self.mux.lock:
            try:
                self.mux.ensure_selected(self.channel)
                return getattr(self.mux.bus, method)(*args)
            except OSError:
                self.mux.forget_selection()  # a glitch may have reset or confused the mux
                raise

    def write_quick(self, i2c_addr: int, force: bool | None = None) -> None:
        self._call("write_quick", i2c_addr)

    def read_byte(self, i2c_addr: int, force: bool | None = None) -> int:
        return self._call("read_byte", i2c_addr)

    def write_byte(self, i2c_addr: int, value: int, force: bool | None = None) -> None:
        self._call("write_byte", i2c_addr, value)

    def read_byte_data(self, i2c_addr: int, register: int, force: bool | None = None) -> int:
        return self._call("read_byte_data", i2c_addr, register)

    def write_byte_data(
        self, i2c_addr: int, register: int, value: int, force: bool | None = None
    ) -> None:
        self._call("write_byte_data", i2c_addr, register, value)

    def read_word_data(self, i2c_addr: int, register: int, force: bool | None = None) -> int:
        return self._call("read_word_data", i2c_addr, register)

    def write_word_data(
        self, i2c_addr: int, register: int, value: int, force: bool | None = None
    ) -> None:
        self._call("write_word_data", i2c_addr, register, value)

    def read_i2c_block_data(
        self, i2c_addr: int, register: int, length: int, force: bool | None = None
    ) -> list[int]:
        return self._call("read_i2c_block_data", i2c_addr, register, length)

    def write_i2c_block_data(
        self, i2c_addr: int, register: int, data: Sequence[int], force: bool | None = None
    ) -> None:
        self._call("write_i2c_block_data", i2c_addr, register, data)

    def i2c_rdwr(self, *i2c_msgs: i2c_msg) -> None:
        self._call("i2c_rdwr", *i2c_msgs)

    def close(self) -> None:
        """Nothing to release: the upstream bus belongs to whoever opened it."""

    def __enter__(self) -> TCA9548AChannel:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
