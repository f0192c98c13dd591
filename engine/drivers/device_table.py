"""The devices claimed on one bus: who holds which address, and each one's record.

One :class:`DeviceTable` per :class:`~engine.drivers.bus_manager.BusManager`. A resource
has one owner, and a conflict names the holder (``I2C 0x29 on bus 1 is already used by
tof_left``). The table is not locked on its own: its manager calls it holding its lock.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.drivers.bus_errors import AddressConflictError
from engine.drivers.device_stats import DeviceRecord

__all__ = ["DeviceTable"]


class DeviceTable:
    """Claims by device name and by address (``None``: the whole bus), and how many are
    offline. ``place(address)`` words an address for messages (``I2C 0x29 on bus 1``)."""

    def __init__(self, place: Callable[[int | None], str], *, latency_window: int) -> None:
        self._place = place
        self._latency_window = latency_window
        self.records: dict[str, DeviceRecord] = {}
        self.holders: dict[int | None, str] = {}
        self.offline = 0
        """How many claimed devices are offline now."""

    def add(
        self, device: str, address: int | None, probe: Callable[[Any], object] | None
    ) -> DeviceRecord:
        """Claim ``address`` for ``device``; AddressConflictError naming the holder if taken."""
        if not isinstance(device, str) or not device:
            raise ValueError(f"a device needs a non-empty name, got {device!r}")
        if address is not None and (
            isinstance(address, bool) or not isinstance(address, int) or address < 0
        ):
            raise ValueError(f"{device}: address must be a non-negative int, got {address!r}")
        if device in self.records:
            held = self.records[device].address
            raise AddressConflictError(
                f"device name {device!r} is already claimed at {self._place(held)}; "
                "give each device its own name"
            )
        holder = self.holders.get(None) or self.holders.get(address)
        if holder is None and address is None and self.holders:
            holder = next(iter(self.holders.values()))
        if holder is not None:
            whole_bus = address is None or None in self.holders
            where = self._place(None if whole_bus else address)
            raise AddressConflictError(f"{where} is already used by {holder}")
        record = DeviceRecord(device, address, probe, self._latency_window)
        self.records[device] = record
        self.holders[address] = device
        return record

    def remove(self, device: str) -> None:
        """Give up ``device``'s claim (nothing happens for a name never claimed)."""
        record = self.records.pop(device, None)
        if record is None:
            return
        del self.holders[record.address]
        if not record.online:
            self.offline -= 1

    def get(self, device: str) -> DeviceRecord:
        """The device's record; unknown names are a programming error."""
        record = self.records.get(device)
        if record is None:
            raise ValueError(
                f"device {device!r} has not claimed an address on {self._place(None)}; "
                "call claim(name, address) first"
            )
        return record

    def flipped(self, record: DeviceRecord) -> None:
        """Count ``record``'s new status (it just went offline or came back)."""
        if self.records.get(record.name) is record:
            self.offline += -1 if record.online else 1

    def due_probes(self, now_s: float) -> list[DeviceRecord]:
        """The offline devices with a probe whose re-probe is due at ``now_s`` seconds."""
        return [
            record
            for record in self.records.values()
            if not record.online and record.probe is not None and now_s >= record.next_probe_s
        ]

    def next_probe_due(self) -> float | None:
        """When the earliest re-probe is due (clock seconds), or None when none is pending."""
        if not self.offline:
            return None
        dues = [
            record.next_probe_s
            for record in self.records.values()
            if not record.online and record.probe is not None
        ]
        return min(dues) if dues else None
