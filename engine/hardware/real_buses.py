"""Where buses come from: the machine's (``smbus2.SMBus(n)``, ``spidev``, the Maestro's
serial port, GPIO lines), opened on demand with errors in words, or the simulated vest's.

The modules of real buses are imported only when a real bus is opened.
"""

from __future__ import annotations

import errno
import logging
import os
from typing import Any, Protocol

from engine.drivers.gpio import OutputLine
from engine.errors import DeviceError
from engine.hardware.config import BusConfig, RobotConfig

_log = logging.getLogger("vest.hardware")

_OPEN_WORDS = {
    errno.ENOENT: "no such device file",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EBUSY: "busy: another program has it",
}


class BusProvider(Protocol):
    """Where the buses come from: the machine's device files, or the simulated vest."""

    def open_i2c(self, bus: BusConfig) -> Any: ...

    def open_spi(self, bus: BusConfig) -> Any: ...

    def serial_port(self, bus: BusConfig) -> Any:
        """A port name (opened by the Maestro driver) or an open pyserial-compatible port."""
        ...

    def output_line(self, offset: int, consumer: str) -> OutputLine: ...


# -- probes: is the chip back, and is it the right chip? ------------------------------------------
class RealBuses:
    """The machine's buses, opened on demand and closed by :meth:`close`."""

    def __init__(self, config: RobotConfig) -> None:
        self.config = config
        self._opened: list[Any] = []

    def open_i2c(self, bus: BusConfig) -> Any:
        import smbus2  # only on a robot

        try:
            handle = smbus2.SMBus(bus.number)
        except OSError as error:
            hint = {
                errno.ENOENT: "enable I2C (raspi-config, or the board's device tree) and check N",
                errno.EACCES: "add yourself to the i2c group",
                errno.EPERM: "add yourself to the i2c group",
            }.get(error.errno or 0, "")
            raise self._error(bus, error, hint) from error
        self._opened.append(handle)
        return handle

    def open_spi(self, bus: BusConfig) -> Any:
        try:
            import spidev  # type: ignore[import-not-found]  # only on a robot
        except ImportError as error:
            raise DeviceError(
                f"{bus.describe()} ({bus.path}): the spidev package is not installed "
                "(pip install spidev)"
            ) from error
        node = spidev.SpiDev()
        try:
            node.open(bus.number, bus.chip_select)
        except OSError as error:
            raise self._error(bus, error, "enable SPI and add yourself to the spi group") from error
        self._opened.append(node)
        return node

    def serial_port(self, bus: BusConfig) -> Any:
        return bus.port

    def output_line(self, offset: int, consumer: str) -> OutputLine:
        from engine.drivers.gpio import GpioOutputLine

        line = GpioOutputLine(self.config.gpio_chip, offset, consumer=consumer)
        self._opened.append(line)
        return line

    @staticmethod
    def _error(bus: BusConfig, error: OSError, hint: str) -> DeviceError:
        code = error.errno or errno.EIO
        words = _OPEN_WORDS.get(code, os.strerror(code).lower())
        failure = DeviceError(
            f"cannot open {bus.describe()} ({bus.path}): {words}" + (f"; {hint}" if hint else "")
        )
        failure.errno = code  # kept for callers, out of the message a person reads
        return failure

    def close(self) -> None:
        for thing in reversed(self._opened):
            try:
                thing.close()
            except OSError as error:
                _log.warning("closing %r: %s", thing, error)
        self._opened.clear()


# -- the hardware ---------------------------------------------------------------------------------
