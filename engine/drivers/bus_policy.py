"""The rules a bus manager applies to failing transactions: retries, offline, re-probes.

:class:`BusPolicy` holds the numbers (how many retries, how long to back off, after how
many failures a device goes offline, how often it is re-probed) and applies them to a
device's :class:`~engine.drivers.device_stats.DeviceRecord`: whether a bus error is worth
another try, whether a routine poll is refused, what a finished transaction does to the
device's status, and the message of a transaction that failed for good. It never touches
a bus or a thread; the :class:`~engine.drivers.bus_manager.BusManager` calls it holding
its lock, with times from its clock.
"""

from __future__ import annotations

import errno
from dataclasses import dataclass, field
from enum import IntEnum

from engine.drivers.bus_errors import DeviceOfflineError, TransactionFailedError
from engine.drivers.device_errors import ImplausibleReadingError, describe_exception, errno_in_words
from engine.drivers.device_stats import DeviceRecord
from engine.errors import DeviceError

__all__ = ["RETRYABLE_ERRNOS", "BusPolicy", "Priority"]

#: Errors a second attempt can fix: the chip did not acknowledge (EREMOTEIO, ENXIO), the
#: adapter reported an I/O error or a timeout (a chip stretching the clock, a glitch), or
#: the adapter was busy (EAGAIN, also reported as arbitration loss on multi-master buses).
RETRYABLE_ERRNOS: frozenset[int] = frozenset(
    {errno.EREMOTEIO, errno.ENXIO, errno.EIO, errno.ETIMEDOUT, errno.EAGAIN}
)


class Priority(IntEnum):
    """Which transaction runs first; lower values first, FIFO within a value."""

    REQUEST = 0
    """Someone is waiting for the answer (an on-request read from a tree, a driver's setup)."""
    POLL = 1
    """Routine polling; refused without touching the bus while the device is offline."""


@dataclass(frozen=True)
class BusPolicy:
    """Retries and the offline rule of one bus.

    - ``retries``: extra attempts after a retryable error (``retry_errnos``), each after a
      backoff of ``backoff_s * 2**n`` seconds (n = 0, 1, ...) capped at ``max_backoff_s``.
    - ``offline_after``: consecutive failed transactions that mark a device offline.
    - ``probe_interval_s``: seconds between re-probes of an offline device.
    """

    retries: int = 2
    backoff_s: float = 0.001
    max_backoff_s: float = 0.05
    offline_after: int = 3
    probe_interval_s: float = 2.0
    retry_errnos: frozenset[int] = field(default=RETRYABLE_ERRNOS)

    def __post_init__(self) -> None:
        if self.retries < 0:
            raise ValueError(f"retries must be 0 or more, got {self.retries}")
        if self.backoff_s < 0 or self.max_backoff_s < 0:
            raise ValueError(
                f"backoff must not be negative, got backoff_s={self.backoff_s}, "
                f"max_backoff_s={self.max_backoff_s}"
            )
        if self.offline_after < 1:
            raise ValueError(f"offline_after must be 1 or more, got {self.offline_after}")
        if self.probe_interval_s <= 0:
            raise ValueError(f"probe_interval_s must be positive, got {self.probe_interval_s}")
        object.__setattr__(self, "retry_errnos", frozenset(self.retry_errnos))

    # -- one transaction -----------------------------------------------------------------
    def backoff_for(self, attempt: int) -> float:
        """Seconds to wait after failed attempt number ``attempt`` (1, 2, ...)."""
        return min(self.backoff_s * 2.0 ** (attempt - 1), self.max_backoff_s)

    def retryable(self, exc: OSError) -> bool:
        """Whether another attempt may fix ``exc``: a bus errno, not a driver's verdict."""
        return not isinstance(exc, DeviceError) and exc.errno in self.retry_errnos

    def attempts(self, record: DeviceRecord, now_s: float) -> int:
        """How many tries a transaction of ``record`` gets (lock held).

        An offline device gets one, and that transaction is its re-probe when it has no
        probe of its own.
        """
        if record.online:
            return self.retries + 1
        if record.probe is None:
            record.probes += 1
            record.next_probe_s = now_s + self.probe_interval_s
        return 1

    def refusal(
        self, record: DeviceRecord, priority: Priority, now_s: float, place: str
    ) -> DeviceOfflineError | None:
        """Why a transaction must not reach the bus now (lock held), or None."""
        if record.online or priority is Priority.REQUEST or now_s >= record.next_probe_s:
            return None
        record.refused += 1
        return DeviceOfflineError(
            f"{record.name} ({place}) is offline after "
            f"{record.consecutive_failures} failed transactions (last: {record.last_error}); "
            f"next re-probe in {record.next_probe_s - now_s:.1f} s",
            device=record.name,
        )

    # -- after it ------------------------------------------------------------------------
    def settle(
        self,
        record: DeviceRecord,
        now_s: float,
        error: BaseException | None,
        bus_failure: bool,
    ) -> bool | None:
        """Apply a finished transaction's outcome (lock held): True if it took the device
        offline, False if it brought it back, None if its status did not change."""
        if error is None:
            record.consecutive_failures = 0
            if not record.online:
                self.set_online(record, True, now_s)
                return False
            return None
        self.count_error(record, error)
        if not bus_failure:
            return None  # a driver bug says nothing about the device
        record.consecutive_failures += 1
        if record.online and record.consecutive_failures >= self.offline_after:
            self.set_online(record, False, now_s)
            return True
        return None

    @staticmethod
    def count_error(record: DeviceRecord, error: BaseException) -> None:
        """Count a failed transaction, or an implausible reading found after one."""
        record.errors += 1
        if isinstance(error, ImplausibleReadingError):
            record.implausible += 1
        record.last_error = describe_exception(error)

    def set_online(self, record: DeviceRecord, online: bool, now_s: float) -> None:
        """Flip a device's status (lock held); going offline schedules its re-probe."""
        record.online = online
        if online:
            record.consecutive_failures = 0
        else:
            record.next_probe_s = now_s + self.probe_interval_s

    def probed(self, record: DeviceRecord, now_s: float, error: BaseException | None) -> bool:
        """Apply a re-probe's outcome (lock held); True when it brought the device back."""
        record.probes += 1
        if error is not None:
            record.last_error = describe_exception(error)
            record.next_probe_s = now_s + self.probe_interval_s
            return False
        if record.online:
            return False
        self.set_online(record, True, now_s)
        return True

    def failure(
        self, record: DeviceRecord, place: str, exc: OSError, attempts: int, went_offline: bool
    ) -> TransactionFailedError:
        """The error a transaction's caller gets once its retries did not help."""
        code = exc.errno if isinstance(exc.errno, int) else None
        words = errno_in_words(code) if code is not None else describe_exception(exc)
        tries = "1 attempt" if attempts == 1 else f"{attempts} attempts"
        text = f"{record.name} ({place}): {words} after {tries}"
        if went_offline:
            text += (
                f"; {record.name} is now offline and will be re-probed every "
                f"{self.probe_interval_s:g} s"
            )
        failure = TransactionFailedError(text, device=record.name, code=code, attempts=attempts)
        failure.__cause__ = exc
        return failure
