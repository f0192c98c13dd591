"""Errors raised by the bus managers (:mod:`engine.drivers.bus_manager`).

Each names the device, the bus and the address, and where an ``errno`` is involved says
what it means in words (``Remote I/O error``), because the person reading it is usually
looking at a loose cable, not at a stack trace.
"""

from __future__ import annotations

from engine.drivers.device_errors import describe_exception, errno_in_words
from engine.errors import ConfigError, DeviceError

# The bus managers' messages use these; their home is engine.drivers.device_errors.
__all__ = [
    "AddressConflictError",
    "BusClosedError",
    "DeviceOfflineError",
    "TransactionFailedError",
    "describe_exception",
    "errno_in_words",
]


class AddressConflictError(ConfigError):
    """Two devices claimed one address on one bus (or one name twice)."""


class TransactionFailedError(DeviceError):
    """A transaction failed on the bus and its retries, if any, did not help.

    ``errno`` is the code of the last attempt's error (``None`` when it had none).
    """

    def __init__(self, message: str, *, device: str, code: int | None, attempts: int) -> None:
        super().__init__(message)
        self.device = device
        self.errno = code
        self.attempts = attempts


class DeviceOfflineError(DeviceError):
    """A routine poll was refused without touching the bus: the device is offline."""

    def __init__(self, message: str, *, device: str) -> None:
        super().__init__(message)
        self.device = device


class BusClosedError(DeviceError):
    """The bus manager was closed before the transaction could run."""

    def __init__(self, message: str, *, device: str) -> None:
        super().__init__(message)
        self.device = device
