"""Whether each device works: ``/devices/<name>/ok`` on the blackboard.

:class:`DeviceHealth` keeps it true while the bus manager has the device online and its
driver reads sensible answers, and stages each change.
"""

from __future__ import annotations

import threading

from engine.blackboard.board import Blackboard


def ok_key(device: str) -> str:
    """``/devices/<device>/ok``."""
    return f"/devices/{device}/ok"


class DeviceHealth:
    """Whether one device works, staged as ``/devices/<name>/ok`` when it changes.

    Two opinions make it: the bus manager's (online / offline, from its ``on_status``) and
    the driver's (its answers make sense: identity, conversions finishing). ``last_error``
    says why it last failed. Thread-safe.
    """

    def __init__(self, name: str, blackboard: Blackboard | None) -> None:
        self.name = name
        self.blackboard = blackboard
        self._lock = threading.Lock()
        self._bus_ok = True
        self._driver_ok = True
        self._shown: bool | None = None
        self.last_error: str | None = None
        self.changes = 0

    @property
    def ok(self) -> bool:
        return self._bus_ok and self._driver_ok

    @property
    def driver_ok(self) -> bool:
        """The driver's last answers made sense."""
        return self._driver_ok

    def bus_status(self, ok: bool) -> None:
        """The bus manager's ``on_status``: online (True) or offline (False)."""
        with self._lock:
            self._bus_ok = ok
            self._publish()

    def driver_status(self, ok: bool, why: str | None = None) -> None:
        """The driver's answers make sense (True), or stopped making sense because ``why``."""
        with self._lock:
            self._driver_ok = ok
            if why is not None:
                self.last_error = why
            self._publish()

    def _publish(self) -> None:
        ok = self.ok
        if ok == self._shown:
            return
        self._shown = ok
        self.changes += 1
        if self.blackboard is not None:
            self.blackboard.stage(ok_key(self.name), ok)
