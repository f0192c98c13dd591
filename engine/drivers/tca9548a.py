"""TI TCA9548A 8-channel I2C multiplexer (addresses 0x70..0x77).

The chip has one register, the control byte, written and read without a register pointer:
bit n connects downstream channel n to the upstream bus. It lets several chips with the
same fixed address (three VL53L0X at 0x29) sit on one bus, one per channel.

:meth:`TCA9548A.channel_bus` returns an ``smbus2.SMBus``-compatible object for one channel:
each call selects that channel (when it is not already the selected one) and forwards,
holding the multiplexer's lock, so traffic for two channels is never interleaved.

The upstream bus is one adapter shared by the chips on it and the chips behind every
channel. ``smbus2`` keeps the target address as state of the open file (``ioctl
I2C_SLAVE``, then the transfer), so two threads using one ``SMBus`` at once can send a
transfer to the other's chip. Give the multiplexer a :class:`LockedBus` and use that same
object for the upstream chips: each call then holds one lock, and a channel's selection and
transfer hold it together, so every access to the adapter is serialized.

Note: 0x70 is also the default address of the vest's SRF02 ranger; with both on one bus,
strap the TCA9548A to 0x71..0x77 (pins A0..A2).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import device_error
from engine.drivers.forwarding_bus import ForwardingI2C, call_on
from engine.drivers.tca9548a_registers import ADDRESSES, CHANNELS, CONTROL_NONE

CHIP = "TCA9548A"


def channel_mask(channel: int) -> int:
    """The control byte that connects ``channel`` (0..7) alone."""
    if not 0 <= channel < CHANNELS:
        raise ValueError(f"{CHIP} channel must be 0..{CHANNELS - 1}, got {channel}")
    return 1 << channel


class LockedBus(ForwardingI2C):
    """An ``smbus2.SMBus``-compatible view of ``bus`` whose every call holds :attr:`lock`.

    Hand the same object to the bus manager of the upstream chips and to the
    :class:`TCA9548A`: channel traffic (selection and transfer) and upstream traffic then
    never reach the adapter at the same time. ``lock`` is re-entrant, so a channel can hold
    it across its selection and transfer.
    """

    def __init__(self, bus: I2CBus, *, lock: threading.RLock | None = None) -> None:
        self.bus = bus
        self.lock = lock if lock is not None else threading.RLock()

    def __repr__(self) -> str:
        return f"LockedBus({self.bus!r})"

    def _forward(self, method: str, *args: Any) -> Any:
        with self.lock:
            return call_on(self.bus, method, *args)


class TCA9548A:
    """A TCA9548A on ``bus``.

    Options (keyword-only):

    - ``address``: 0x70..0x77 (pins A0..A2).
    - ``lock``: held while a channel is selected and used; by default the lock of a
      :class:`LockedBus` ``bus``, else a lock of its own (then nothing else may use ``bus``).
    - ``check``: read the control byte now, raising :class:`DeviceError` when the chip does
      not answer (it has no identity register). With ``check=False`` nothing is sent yet:
      the first channel access writes the control byte, so a multiplexer that is late or
      missing fails those accesses as ordinary bus errors, retried and re-probed by their
      bus manager.
    - ``on_answer(ok, why)``: called when the chip starts or stops answering its control
      byte (``why`` says what failed), from the thread that made the access.
    """

    def __init__(
        self,
        bus: I2CBus,
        *,
        address: int = 0x70,
        lock: threading.RLock | None = None,
        check: bool = True,
        on_answer: Callable[[bool, str | None], None] | None = None,
    ) -> None:
        if address not in ADDRESSES:
            raise ValueError(f"{CHIP} address must be 0x70..0x77, got 0x{address:02X}")
        self.bus = bus
        self.address = address
        if lock is None:
            lock = bus.lock if isinstance(bus, LockedBus) else threading.RLock()
        self._lock = lock
        self._on_answer = on_answer
        self.answering: bool | None = None
        """Whether the chip answered its last control-byte access (None: not asked yet)."""
        self._control: int | None = None
        if check:
            try:
                self.selected()
            except OSError as err:
                where = f"{CHIP} at 0x{address:02X}"
                raise device_error(f"{where} did not answer: {err.strerror or err}", err) from err

    def __repr__(self) -> str:
        return f"TCA9548A(address=0x{self.address:02X})"

    @property
    def lock(self) -> threading.RLock:
        """Held while a channel is selected and used (shared with a :class:`LockedBus`)."""
        return self._lock

    def select(self, channel: int) -> None:
        """Connect ``channel`` (0..7) alone to the upstream bus."""
        self._write_control(channel_mask(channel))

    def deselect_all(self) -> None:
        """Disconnect every channel."""
        self._write_control(CONTROL_NONE)

    def selected(self) -> list[int]:
        """The channels connected now, as the chip reports them (bus errors as raised)."""
        with self._lock:
            try:
                control = self.bus.read_byte(self.address)
            except OSError as err:
                self._answered(err)
                raise
            self._control = control
            self._answered(None)
        return [channel for channel in range(CHANNELS) if control & (1 << channel)]

    def _write_control(self, control: int) -> None:
        with self._lock:
            self._control = None  # unknown until the write has gone through
            try:
                self.bus.write_byte(self.address, control)
            except OSError as err:
                self._answered(err)
                raise
            self._control = control
            self._answered(None)

    def _answered(self, error: OSError | None) -> None:
        """Note whether the chip answered; tell ``on_answer`` when that changed."""
        ok = error is None
        if ok == self.answering:
            return
        self.answering = ok
        if self._on_answer is not None:
            why = None if error is None else f"{CHIP} at 0x{self.address:02X}: {error}"
            self._on_answer(ok, why)

    def ensure_selected(self, channel: int) -> None:
        """Select ``channel`` unless it already is the only one (call holding :attr:`lock`)."""
        mask = channel_mask(channel)
        if self._control != mask:
            self._write_control(mask)

    def forget_selection(self) -> None:
        """Make the next channel access write the control byte again (after a bus error)."""
        self._control = None

    def channel_bus(self, channel: int) -> TCA9548AChannel:
        """An ``smbus2.SMBus``-compatible bus reaching the chips behind ``channel``."""
        channel_mask(channel)
        return TCA9548AChannel(self, channel)


class TCA9548AChannel(ForwardingI2C):
    """One downstream channel of a :class:`TCA9548A`, with the ``smbus2.SMBus`` interface."""

    def __init__(self, mux: TCA9548A, channel: int) -> None:
        self.mux = mux
        self.channel = channel

    def __repr__(self) -> str:
        return f"{self.mux!r}.channel_bus({self.channel})"

    def _forward(self, method: str, *args: Any) -> Any:
        with self.mux.lock:
            try:
                self.mux.ensure_selected(self.channel)
                return call_on(self.mux.bus, method, *args)
            except OSError:
                self.mux.forget_selection()  # a glitch may have reset or confused the mux
                raise

    def __enter__(self) -> TCA9548AChannel:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
