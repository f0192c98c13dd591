"""The errors drivers raise, and an errno in words: one place for every driver.

The person reading a driver's error is usually looking at a loose cable or a chip gone
wrong, not at a stack trace, so each message names the chip, its address (or port) and
says the errno's meaning in words.

- :func:`errno_in_words`: ``121`` -> ``'Remote I/O error (EREMOTEIO, errno 121)'``, or the
  caller's advice for that code (``permission denied: add yourself to the dialout group``).
- :func:`device_error`: a :class:`~engine.errors.DeviceError` that keeps the errno of the
  bus error behind it; :func:`not_found`: the one a first contact raises.
- :class:`ImplausibleReadingError`: a chip answered a value it cannot report (a garbled
  transfer, a failing chip); the value is refused, never passed on.
"""

from __future__ import annotations

import errno as errno_codes
import os
from collections.abc import Mapping

from engine.errors import DeviceError

__all__ = [
    "ImplausibleReadingError",
    "describe_exception",
    "device_error",
    "errno_in_words",
    "i2c_place",
    "not_found",
]


def errno_in_words(code: int | None, advice: Mapping[int, str] | None = None) -> str:
    """An errno as words: ``advice[code]`` when given, else its meaning, name and number.

    ``121`` -> ``'Remote I/O error (EREMOTEIO, errno 121)'``; ``None`` -> ``'unknown error'``.
    """
    if code is None:
        return "unknown error"
    if advice is not None and code in advice:
        return advice[code]
    name = errno_codes.errorcode.get(code, "unknown")
    return f"{os.strerror(code)} ({name}, errno {code})"


def describe_exception(exc: BaseException) -> str:
    """A one-line text for statistics and messages: errno in words, or type and message."""
    code = getattr(exc, "errno", None)
    if isinstance(exc, OSError) and isinstance(code, int) and not isinstance(exc, DeviceError):
        return errno_in_words(code)
    return f"{type(exc).__name__}: {exc}"


def device_error(message: str, cause: OSError | None = None) -> DeviceError:
    """A DeviceError saying ``message`` that keeps the errno of ``cause``, if it had one."""
    code = cause.errno if cause is not None else None
    return DeviceError(code, message) if isinstance(code, int) else DeviceError(message)


def not_found(chip: str, address: int, error: OSError) -> DeviceError:
    """The bus error of a first contact: ``MCP9808 not found at I2C 0x18: <why>``."""
    return device_error(
        f"{chip} not found at I2C 0x{address:02X}: {error.strerror or error}", error
    )


def i2c_place(address: int) -> str:
    """``I2C 0x18``: where an I2C chip is, for messages."""
    return f"I2C 0x{address:02X}"


class ImplausibleReadingError(DeviceError, ValueError):
    """A chip answered a value it cannot report; the reading is refused.

    ``chip`` (``"MCP9808"``), ``place`` (``"I2C 0x18"``, ``"SPI"``), ``what`` was read
    (``"temperature"``), the ``value`` as read (with its unit) and the ``plausible`` range
    (``"-40..125 degC"``). A bus manager counts these per device (``implausible`` in its
    statistics).
    """

    def __init__(self, *, chip: str, place: str, what: str, value: str, plausible: str) -> None:
        super().__init__(
            f"{chip} at {place}: {what} {value} is outside what the chip can report "
            f"({plausible}); the reading is refused (a garbled transfer or a failing chip)"
        )
        self.chip = chip
        self.place = place
        self.what = what
        self.value = value
        self.plausible = plausible

    def __reduce__(self) -> tuple[object, ...]:
        # OSError's pickling passes args positionally; ours are keyword-only.
        return (_rebuild, (self.chip, self.place, self.what, self.value, self.plausible))


def _rebuild(
    chip: str, place: str, what: str, value: str, plausible: str
) -> ImplausibleReadingError:
    return ImplausibleReadingError(
        chip=chip, place=place, what=what, value=value, plausible=plausible
    )
