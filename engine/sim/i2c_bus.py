"""A simulated I2C bus with the ``smbus2.SMBus`` interface, and the base of chip models.

A chip model sees raw transfers, as the chip does on the wire: a write transfer (the first
byte is usually a register pointer) and a read transfer (bytes from wherever the chip's
pointer is). SMBus helpers are composed of those transfers exactly as the Linux i2c-dev
driver does, so byte order, auto-increment and repeated starts behave like the real bus.

Faults are injected per address (NACK, unplugged, garbage) or for the whole bus (a device
holding SDA low), each for a window of time on the injected clock.
"""

from __future__ import annotations

import errno
import os
import random
import threading
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from engine.clock import Clock
from engine.drivers.bus_protocols import I2CBus

I2C_M_RD = 0x0001


def bus_error(code: int, address: int | None = None) -> OSError:
    """An ``OSError`` as the i2c-dev driver raises it (errno and its words)."""
    where = f" (address 0x{address:02X})" if address is not None else ""
    return OSError(code, os.strerror(code) + where)


class SimI2CDevice:
    """Base of a chip model on a :class:`SimI2CBus`.

    Subclasses implement :meth:`write` and :meth:`read`; both run with the bus lock held,
    so a model never sees two transfers at once.
    """

    def __init__(self, address: int) -> None:
        if not 0x03 <= address <= 0x77:
            raise ValueError(f"7-bit I2C address 0x{address:02X} is outside 0x03..0x77")
        self.address = address

    def write(self, data: bytes) -> None:
        """A write transfer addressed to this chip (``data`` may be empty: a quick write)."""
        raise NotImplementedError

    def read(self, length: int) -> bytes:
        """A read transfer of ``length`` bytes."""
        raise NotImplementedError


class RegisterFile:
    """Byte registers with a pointer that auto-increments on reads and writes.

    A convenience for chips that behave this way (ADS-style 16-bit chips do not; they
    override the transfers themselves).
    """

    def __init__(self, size: int = 256, *, wrap: int | None = None) -> None:
        self.bytes = bytearray(size)
        self.pointer = 0
        self._wrap = wrap if wrap is not None else size

    def advance(self) -> None:
        self.pointer = (self.pointer + 1) % self._wrap


@dataclass
class _Fault:
    kind: str  # "nack" | "unplugged" | "garbage" | "hold"
    until_s: float


class SimI2CBus(I2CBus):
    """An ``smbus2.SMBus``-compatible bus whose chips are Python models.

    ``bus_number`` is only used in messages. Thread-safe: one transfer at a time.
    """

    def __init__(self, clock: Clock, *, bus_number: int = 1, seed: int = 0) -> None:
        self.clock = clock
        self.bus_number = bus_number
        self._devices: dict[int, SimI2CDevice] = {}
        self._faults: dict[int | None, _Fault] = {}
        self._lock = threading.RLock()
        self._random = random.Random(seed)
        self.transfers = 0

    # -- wiring -------------------------------------------------------------------------
    def attach(self, device: SimI2CDevice) -> SimI2CDevice:
        """Solder ``device`` onto the bus; two chips on one address is an error."""
        with self._lock:
            holder = self._devices.get(device.address)
            if holder is not None:
                raise ValueError(
                    f"I2C 0x{device.address:02X} on simulated bus {self.bus_number} is "
                    f"already used by {type(holder).__name__}"
                )
            self._devices[device.address] = device
        return device

    def detach(self, address: int) -> None:
        with self._lock:
            self._devices.pop(address, None)

    def readdress(self, old: int, new: int) -> None:
        """Move a chip to a new address (a chip that changes its own address calls this)."""
        with self._lock:
            device = self._devices.pop(old)
            device.address = new
            self._devices[new] = device

    def device_at(self, address: int) -> SimI2CDevice | None:
        return self._devices.get(address)

    @property
    def addresses(self) -> list[int]:
        return sorted(self._devices)

    # -- faults -------------------------------------------------------------------------
    def inject(self, kind: str, seconds: float, address: int | None = None) -> None:
        """Make ``address`` (or the whole bus when ``kind == 'hold'``) misbehave for a while.

        Kinds: ``nack`` (the chip does not acknowledge), ``unplugged`` (no chip answers),
        ``garbage`` (reads return random bytes), ``hold`` (a chip holds SDA low; every
        transfer on the bus times out).
        """
        if kind not in {"nack", "unplugged", "garbage", "hold"}:
            raise ValueError(f"unknown fault {kind!r}: use nack, unplugged, garbage or hold")
        key = None if kind == "hold" else address
        with self._lock:
            self._faults[key] = _Fault(kind, self.clock.now() + seconds)

    def fault_at(self, address: int) -> str | None:
        """The fault injected at ``address`` that is still active, if any (not ``hold``)."""
        with self._lock:
            return self._active_fault(address)

    def _active_fault(self, key: int | None) -> str | None:
        fault = self._faults.get(key)
        if fault is None:
            return None
        if self.clock.now() >= fault.until_s:
            del self._faults[key]
            return None
        return fault.kind

    def _target(self, address: int) -> tuple[SimI2CDevice, bool]:
        """The chip at ``address`` and whether its reads are garbage, or the bus error."""
        if self._active_fault(None) == "hold":
            raise bus_error(errno.ETIMEDOUT, address)
        kind = self._active_fault(address)
        device = self._devices.get(address)
        if device is None or kind in {"nack", "unplugged"}:
            raise bus_error(errno.EREMOTEIO if device is not None else errno.ENXIO, address)
        return device, kind == "garbage"

    # -- raw transfers ------------------------------------------------------------------
    def transfer(self, messages: Sequence[tuple[int, bool, bytes | int]]) -> list[bytes]:
        """Run a combined transaction: ``(address, is_read, data_or_length)`` per message.

        Returns the bytes of each read message, in order.
        """
        results: list[bytes] = []
        with self._lock:
            self.transfers += 1
            for address, is_read, payload in messages:
                device, garbage = self._target(address)
                if is_read:
                    length = int(payload)
                    data = device.read(length)
                    if garbage:
                        data = bytes(self._random.randrange(256) for _ in range(length))
                    results.append(bytes(data))
                else:
                    device.write(bytes(payload))
        return results

    def _write(self, address: int, data: Iterable[int]) -> None:
        self.transfer([(address, False, bytes(data))])

    def _write_read(self, address: int, register: int, length: int) -> bytes:
        return self.transfer([(address, False, bytes([register])), (address, True, length)])[0]

    # -- smbus2.SMBus interface -----------------------------------------------------------
    def read_byte(self, i2c_addr: int, force: bool | None = None) -> int:
        return self.transfer([(i2c_addr, True, 1)])[0][0]

    def write_byte(self, i2c_addr: int, value: int, force: bool | None = None) -> None:
        self._write(i2c_addr, [value & 0xFF])

    def read_byte_data(self, i2c_addr: int, register: int, force: bool | None = None) -> int:
        return self._write_read(i2c_addr, register, 1)[0]

    def write_byte_data(
        self, i2c_addr: int, register: int, value: int, force: bool | None = None
    ) -> None:
        self._write(i2c_addr, [register & 0xFF, value & 0xFF])

    def read_i2c_block_data(
        self, i2c_addr: int, register: int, length: int, force: bool | None = None
    ) -> list[int]:
        if not 0 < length <= 32:
            raise ValueError(f"I2C block length must be 1..32, got {length}")
        return list(self._write_read(i2c_addr, register, length))

    def write_i2c_block_data(
        self, i2c_addr: int, register: int, data: Sequence[int], force: bool | None = None
    ) -> None:
        if len(data) > 32:
            raise ValueError(f"I2C block length must be at most 32, got {len(data)}")
        self._write(i2c_addr, [register & 0xFF, *(b & 0xFF for b in data)])

    def close(self) -> None:
        """Nothing to release: the bus was not opened from a device file."""

    def __enter__(self) -> SimI2CBus:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
