"""Errors raised by the bus managers (:mod:`engine.drivers.bus_manager`).

Each names the device, the bus and the address, and where an ``errno`` is involved says
what it means in words (``Remote I/O error``), because the person reading it is usually
looking at a loose cable, not at a stack trace.
"""

from __future__ import annotations

import errno as errno_codes
import os

from engine.errors import ConfigError, DeviceError


def errno_in_words(code: int) -> str:
    """``121`` -> ``'Remote I/O error (EREMOTEIO, errno 121)'``."""
    name = errno_codes.errorcode.get(code, "unknown")
    return f"{os.strerror(code)} ({name}, errno {code})"


def describe_exception(exc: BaseException) -> str:
    """A one-line text for statistics and messages: errno in words, or type and message."""
    code = getattr(exc, "errno", None)
    if isinstance(exc, OSError) and isinstance(code, int) and not isinstance(exc, DeviceError):
        return errno_in_words(code)
    return f"{type(exc).__name__}: {exc}"


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
