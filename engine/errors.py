"""The project's error types.

Every error roots at :class:`VestError` and also inherits the matching builtin, so callers
can catch either ``VestError`` or, say, ``ValueError``. Messages name the thing, the value
and the place.
"""

from __future__ import annotations


class VestError(Exception):
    """Root of every error raised by vest."""


class UsageError(VestError, ValueError):
    """The command line is wrong in a way argparse cannot see (exit 2)."""


class ConfigError(VestError, ValueError):
    """A person's input (a YAML file, a CLI argument, a config) is wrong."""


class DeviceError(VestError, OSError):
    """A device could not be reached or answered something it should not.

    ``DeviceError(errno, message)`` keeps the errno for code, and reads as the message
    alone (not Python's ``[Errno 121] ...``): the message already says it in words.
    """

    def __str__(self) -> str:
        if self.strerror:
            return str(self.strerror)
        return super().__str__()


class ServiceError(VestError, RuntimeError):
    """A service (speech, LEDs, servos, sensors, IoT) could not do what was asked."""
