"""The bus interfaces every driver speaks, written once.

A driver never opens a bus: it is handed an object with one of these interfaces, so the
same driver runs on the robot's ``/dev/i2c-1`` (``smbus2.SMBus``), on a register-level
model (:mod:`engine.sim`), behind a multiplexer channel or a bus manager's
transaction (:class:`~engine.drivers.forwarding_bus.ForwardingI2C`), or on anyone else's
compatible object. These are structural types (``typing.Protocol``): nothing inherits them,
and ``isinstance(bus, I2CBus)`` checks that the methods are there.

- :class:`I2CBus`: the ``smbus2.SMBus`` methods. Registers are 8-bit addresses, values
  bytes (0..255); ``*_word_data`` are SMBus words, least significant byte first.
- :class:`SpiDevice`: the ``spidev.SpiDev`` methods; ``mode`` is 0..3, ``max_speed_hz`` the
  clock in Hz.
- :class:`SerialPort`: the part of ``serial.Serial`` a driver uses; ``timeout`` is in seconds
  (``None``: a read waits forever, which no driver accepts).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol, runtime_checkable

__all__ = ["I2CBus", "SerialPort", "SpiDevice"]


@runtime_checkable
class I2CBus(Protocol):
    """An ``smbus2.SMBus``-compatible I2C bus (``i2c_addr`` is the chip's 7-bit address)."""

    def read_byte(self, i2c_addr: int, force: bool | None = None) -> int: ...

    def write_byte(self, i2c_addr: int, value: int, force: bool | None = None) -> None: ...

    def read_byte_data(self, i2c_addr: int, register: int, force: bool | None = None) -> int: ...

    def write_byte_data(
        self, i2c_addr: int, register: int, value: int, force: bool | None = None
    ) -> None: ...

    def read_i2c_block_data(
        self, i2c_addr: int, register: int, length: int, force: bool | None = None
    ) -> list[int]: ...

    def write_i2c_block_data(
        self, i2c_addr: int, register: int, data: Sequence[int], force: bool | None = None
    ) -> None: ...

    def close(self) -> None: ...


@runtime_checkable
class SpiDevice(Protocol):
    """An ``spidev.SpiDev``-compatible SPI node, opened by its owner."""

    mode: int
    max_speed_hz: int

    def xfer(self, values: Sequence[int], speed_hz: int = 0) -> list[int]: ...

    def xfer2(self, values: Sequence[int], speed_hz: int = 0) -> list[int]: ...

    def readbytes(self, length: int) -> list[int]: ...

    def writebytes(self, values: Sequence[int]) -> None: ...


@runtime_checkable
class SerialPort(Protocol):
    """The part of a pyserial ``serial.Serial`` a driver uses; ``timeout`` in seconds."""

    timeout: float | None

    def write(self, data: bytes, /) -> int | None: ...

    def read(self, size: int = 1, /) -> bytes: ...

    def flush(self) -> None: ...

    def reset_input_buffer(self) -> None: ...

    def close(self) -> None: ...
