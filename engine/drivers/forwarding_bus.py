"""The ``smbus2.SMBus`` interface, forwarded: the base of buses that wrap another bus.

A wrapper (a bus under a lock, a multiplexer's channel, a bus-manager transaction)
implements :meth:`ForwardingI2C._forward` once; every SMBus method goes through it by
name with its arguments, so the interface is written in one place.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from engine.drivers.bus_protocols import I2CBus

WRITE_EACH = "write_byte_data_each"
"""Several register writes as one access of the wrapper (:func:`write_each`)."""


def call_on(bus: Any, method: str, *args: Any) -> Any:
    """``bus.method(*args)``; :data:`WRITE_EACH` on a bus without it (smbus2's own, a
    simulated one) is its writes one after another."""
    if method == WRITE_EACH and not hasattr(bus, WRITE_EACH):
        address, writes = args
        for register, value in writes:
            bus.write_byte_data(address, register, value)
        return None
    return getattr(bus, method)(*args)


def write_each(bus: Any, i2c_addr: int, writes: Sequence[tuple[int, int]]) -> None:
    """Write each ``(register, value)`` to the chip at ``i2c_addr``, in order: on a wrapper
    (the bus manager's transaction, a lock, a multiplexer's channel) as one access, so a
    chip's run of setup writes costs one hand-off, not one each; elsewhere one by one."""
    call_on(bus, WRITE_EACH, i2c_addr, tuple(writes))


class ForwardingI2C(I2CBus):
    """Every ``smbus2.SMBus`` call becomes ``self._forward(method_name, *args)``.

    It declares :class:`~engine.drivers.bus_protocols.I2CBus`, so the type checker holds
    every method to that one interface.
    """

    def _forward(self, method: str, *args: Any) -> Any:
        raise NotImplementedError(f"{type(self).__name__} must implement _forward()")

    def write_byte_data_each(self, i2c_addr: int, writes: Sequence[tuple[int, int]]) -> None:
        """Each ``(register, value)`` written in order, as one access of this wrapper."""
        self._forward(WRITE_EACH, i2c_addr, tuple(writes))

    def read_byte(self, i2c_addr: int, force: bool | None = None) -> int:
        value: int = self._forward("read_byte", i2c_addr)
        return value

    def write_byte(self, i2c_addr: int, value: int, force: bool | None = None) -> None:
        self._forward("write_byte", i2c_addr, value)

    def read_byte_data(self, i2c_addr: int, register: int, force: bool | None = None) -> int:
        value: int = self._forward("read_byte_data", i2c_addr, register)
        return value

    def write_byte_data(
        self, i2c_addr: int, register: int, value: int, force: bool | None = None
    ) -> None:
        self._forward("write_byte_data", i2c_addr, register, value)

    def read_i2c_block_data(
        self, i2c_addr: int, register: int, length: int, force: bool | None = None
    ) -> list[int]:
        data: list[int] = self._forward("read_i2c_block_data", i2c_addr, register, length)
        return data

    def write_i2c_block_data(
        self, i2c_addr: int, register: int, data: Sequence[int], force: bool | None = None
    ) -> None:
        # a copy: the transaction may run later, on another thread
        self._forward("write_i2c_block_data", i2c_addr, register, list(data))

    def close(self) -> None:
        """Nothing to release: the wrapped bus belongs to whoever opened it."""
