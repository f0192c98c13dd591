"""A simulated SPI device node with the ``spidev.SpiDev`` interface, and the base of chip models.

One :class:`SimSpiDev` is one chip select (``/dev/spidevB.D``) with one chip behind it, as
on Linux. A chip model sees frames bit by bit, as the chip does on the wire: the bits
clocked in on MOSI while chip select is low, most significant bit of each byte first. It
answers one MISO bit per clock, or ``None`` where it leaves MISO floating (high
impedance); the node fills floating bits with random ones, as a floating line reads.

Transfer semantics follow the py-spidev documentation: ``xfer2`` (and
``writebytes``, ``readbytes``) hold chip select low for the whole list, while ``xfer``
releases and re-asserts it between bytes, so each byte is a frame of its own.

Settings the chip sees with every frame: ``mode`` (0..3) and the clock (``max_speed_hz``,
or a transfer's own ``speed_hz``). ``lsbfirst`` reverses the bit order of each byte on the
wire; ``cshigh`` and ``no_cs`` leave the chip deselected, so it answers nothing; ``loop``
wires MISO to MOSI. Like the Raspberry Pi's spidev nodes, a fresh node clocks at
125 MHz until told otherwise, far beyond what most SPI chips accept.
"""

from __future__ import annotations

import errno
import os
import random
from collections.abc import Sequence

from engine.drivers.bus_protocols import SpiDevice

Bit = int | None


class SimSpiDevice:
    """Base of a chip model behind a :class:`SimSpiDev`."""

    def frame(self, mosi_bits: Sequence[int], *, mode: int, speed_hz: int) -> list[Bit]:
        """One chip-select-low frame: MOSI bits in, one MISO bit (or ``None``) per clock."""
        raise NotImplementedError


def _bits_of(data: Sequence[int]) -> list[int]:
    return [(byte >> (7 - index)) & 1 for byte in data for index in range(8)]


def _reverse_bits(byte: int) -> int:
    return int(f"{byte:08b}"[::-1], 2)


class SimSpiDev(SpiDevice):
    """An ``spidev.SpiDev``-compatible node with ``chip`` behind its chip select.

    Like ``spidev.SpiDev(bus, device)``, giving ``bus`` and ``device`` opens the node at
    once; with ``None`` call :meth:`open`. Transfers on a closed node raise ``OSError``.
    """

    def __init__(
        self,
        chip: SimSpiDevice,
        bus: int | None = 0,
        device: int | None = 0,
        *,
        seed: int = 0,
    ) -> None:
        self.chip = chip
        self.mode = 0
        self.max_speed_hz = 125_000_000
        self.bits_per_word = 8
        self.lsbfirst = False
        self.cshigh = False
        self.no_cs = False
        self.threewire = False
        self.loop = False
        self.bus: int | None = None
        self.device: int | None = None
        self._open = False
        self._random = random.Random(seed)
        self.frames = 0
        if bus is not None and device is not None:
            self.open(bus, device)

    # -- spidev interface ---------------------------------------------------------------
    def open(self, bus: int, device: int) -> None:
        """Open ``/dev/spidev<bus>.<device>`` (here: mark the node open)."""
        self.bus, self.device = bus, device
        self._open = True

    def close(self) -> None:
        self._open = False

    @property
    def closed(self) -> bool:
        return not self._open

    def xfer(
        self,
        values: Sequence[int],
        speed_hz: int = 0,
        delay_usec: int = 0,
        bits_per_word: int = 0,
    ) -> list[int]:
        """Exchange ``values``, releasing chip select between bytes."""
        return [self._frame([value], speed_hz)[0] for value in self._checked(values)]

    def xfer2(
        self,
        values: Sequence[int],
        speed_hz: int = 0,
        delay_usec: int = 0,
        bits_per_word: int = 0,
    ) -> list[int]:
        """Exchange ``values`` with chip select held low throughout."""
        return self._frame(self._checked(values), speed_hz)

    def writebytes(self, values: Sequence[int]) -> None:
        """Send ``values`` in one frame, discarding what comes back."""
        self._frame(self._checked(values), 0)

    def readbytes(self, length: int) -> list[int]:
        """Clock ``length`` bytes in one frame with MOSI held low."""
        if length < 0:
            raise ValueError(f"readbytes length {length} is negative")
        return self._frame([0] * length, 0)

    def __enter__(self) -> SimSpiDev:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the wire -----------------------------------------------------------------------
    def _checked(self, values: Sequence[int]) -> list[int]:
        if not self._open:
            raise OSError(errno.EBADF, os.strerror(errno.EBADF) + " (SimSpiDev is not open)")
        if self.bits_per_word != 8:
            raise ValueError(f"SimSpiDev models 8-bit words only, not {self.bits_per_word}")
        if not 0 <= self.mode <= 3:
            raise ValueError(f"SPI mode {self.mode} is outside 0..3")
        checked = [int(value) for value in values]
        for value in checked:
            if not 0 <= value <= 0xFF:
                raise ValueError(f"SPI byte {value} is outside 0..255")
        return checked

    def _frame(self, values: list[int], speed_hz: int) -> list[int]:
        self.frames += 1
        if self.loop:
            return list(values)
        on_wire = [_reverse_bits(v) for v in values] if self.lsbfirst else values
        if self.cshigh or self.no_cs:
            miso: list[Bit] = [None] * (8 * len(values))
        else:
            miso = self.chip.frame(
                _bits_of(on_wire), mode=self.mode, speed_hz=speed_hz or self.max_speed_hz
            )
        bits = [self._random.getrandbits(1) if bit is None else bit for bit in miso]
        out = [
            sum(bit << (7 - index) for index, bit in enumerate(bits[start : start + 8]))
            for start in range(0, len(bits), 8)
        ]
        return [_reverse_bits(v) for v in out] if self.lsbfirst else out
