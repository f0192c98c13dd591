"""A model of the TI TCA9548A I2C multiplexer bridging simulated buses.

The chip: one control byte, written and read with no register pointer (a write of several
bytes keeps the last one); bit n connects downstream channel n; power-on (and the RESET
pin) connects none.

The bridge: while channels are selected, the chips on them answer on the upstream bus as
if soldered there. :class:`SimI2CBus` routes by address only, so the model stands a small
proxy on the upstream bus for each address present on the selected channels, and forwards
each of its transfers to the downstream bus that holds the chip (so downstream faults,
timing and re-addressing act as they would). The proxies follow the selection and are
refreshed after every control write and every forwarded transfer (a VL53L0X behind the mux
changing its own address is followed at once). A chip attached to a downstream bus while
its channel is already selected shows up upstream at the next control write or transfer
through the mux: call :meth:`SimTCA9548A.refresh` to make it visible sooner.

When two selected channels hold the same address, both chips see writes and reads return
the bitwise AND of their answers (open-drain wired-AND), as on the real wires.
"""

from __future__ import annotations

import errno
from collections.abc import Sequence
from typing import Protocol

from engine.drivers.tca9548a_registers import ADDRESSES, CHANNELS, CONTROL_NONE
from engine.sim.i2c_bus import SimI2CBus, SimI2CDevice, bus_error


class DownstreamBus(Protocol):
    """What the multiplexer needs from a downstream bus (a :class:`SimI2CBus` has it)."""

    @property
    def addresses(self) -> list[int]: ...

    def transfer(self, messages: Sequence[tuple[int, bool, bytes | int]]) -> list[bytes]: ...


class _Bridged(SimI2CDevice):
    """Stands on the upstream bus for the chip(s) at one address behind the multiplexer."""

    def __init__(self, mux: SimTCA9548A, address: int) -> None:
        super().__init__(address)
        self.mux = mux

    def write(self, data: bytes) -> None:
        self.mux.forward(self.address, False, data)

    def read(self, length: int) -> bytes:
        return self.mux.forward(self.address, True, length)


class SimTCA9548A(SimI2CDevice):
    """A TCA9548A at ``address`` whose channel n is ``downstream[n]``.

    Give ``upstream`` to have it attach itself there and bridge the selected channels; a
    model without an upstream bus only keeps its control byte.
    """

    def __init__(
        self,
        address: int,
        downstream: Sequence[DownstreamBus],
        *,
        upstream: SimI2CBus | None = None,
    ) -> None:
        if address not in ADDRESSES:
            raise ValueError(f"a TCA9548A answers on 0x70..0x77, not 0x{address:02X}")
        if len(downstream) > CHANNELS:
            raise ValueError(f"a TCA9548A has 8 channels, got {len(downstream)} buses")
        super().__init__(address)
        self.downstream = list(downstream)
        self.control = CONTROL_NONE
        self.upstream = upstream
        self._bridged: dict[int, _Bridged] = {}
        if upstream is not None:
            upstream.attach(self)

    # -- the pins -----------------------------------------------------------------------------
    def reset(self) -> None:
        """Pulse the RESET pin: every channel disconnected."""
        self.control = CONTROL_NONE
        self.refresh()

    @property
    def selected_channels(self) -> list[int]:
        return [n for n in range(len(self.downstream)) if self.control & (1 << n)]

    # -- the control register -------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if data:
            self.control = data[-1]  # several bytes: the last one received is kept
            self.refresh()

    def read(self, length: int) -> bytes:
        return bytes([self.control]) * length

    # -- the bridge --------------------------------------------------------------------------
    def _selected_buses(self) -> list[tuple[int, DownstreamBus]]:
        return [(n, self.downstream[n]) for n in self.selected_channels]

    def refresh(self) -> None:
        """Make the upstream bus show exactly the chips on the selected channels."""
        wanted: dict[int, int] = {}
        for channel, bus in self._selected_buses():
            for address in bus.addresses:
                if address != self.address:
                    wanted.setdefault(address, channel)
        if self.upstream is None:
            if wanted:
                raise ValueError(
                    f"simulated TCA9548A at 0x{self.address:02X} was given no upstream bus "
                    f"(upstream=...), so it cannot connect channel {min(wanted.values())}"
                )
            return
        for address in list(self._bridged):
            if address not in wanted:
                proxy = self._bridged.pop(address)
                if self.upstream.device_at(address) is proxy:
                    self.upstream.detach(address)
        for address, channel in wanted.items():
            if address in self._bridged:
                continue
            holder = self.upstream.device_at(address)
            if holder is not None:
                raise ValueError(
                    f"simulated TCA9548A at 0x{self.address:02X}: 0x{address:02X} behind "
                    f"channel {channel} collides with {type(holder).__name__} on the "
                    f"upstream bus"
                )
            self._bridged[address] = _Bridged(self, address)
            self.upstream.attach(self._bridged[address])

    def forward(self, address: int, is_read: bool, payload: bytes | int) -> bytes:
        """One transfer from upstream to the chip(s) at ``address`` on the selected channels."""
        try:
            buses = [bus for _, bus in self._selected_buses() if address in bus.addresses]
            if not buses:
                raise bus_error(errno.ENXIO, address)
            answers: list[bytes] = []
            failure: OSError | None = None
            for bus in buses:
                try:
                    result = bus.transfer([(address, is_read, payload)])
                except OSError as err:
                    failure = failure or err
                    continue
                answers.append(result[0] if is_read else b"")
            if not answers and failure is not None:
                raise failure  # nobody acknowledged
            if not is_read:
                return b""
            merged = bytearray(answers[0])
            for answer in answers[1:]:
                for index, value in enumerate(answer):
                    merged[index] &= value
            return bytes(merged)
        finally:
            self.refresh()
