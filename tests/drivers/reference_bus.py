"""What Adafruit's CircuitPython drivers need to run on the simulated chips, for tests only.

Adafruit's drivers speak to a ``busio.I2C`` (through ``adafruit_bus_device``), import
``micropython.const`` and read ``time``. Here:

- :class:`ReferenceI2C` is the part of ``busio.I2C`` they use, over a :class:`SimI2CBus`:
  each call is one transaction of raw transfers, as on the wire. Every transaction moves
  the simulated clock by its time on the wire (9 bits a byte at ``frequency_hz``), so a
  driver that polls a busy chip sees time pass, and the count of transactions is bounded:
  a driver still polling after ``max_transactions`` fails the test instead of hanging it.
- :class:`SimulatedTime` replaces a driver module's ``time``: ``sleep`` advances the
  simulated clock and ``monotonic`` reads it; nothing waits for real.
- :class:`NvmOff` is a simulated VL53L0X whose NVM never answers, to show the guard works.
- :class:`RecordingBus` is a :class:`SimI2CBus` that keeps every write transfer, so two
  drivers' bring-ups can be compared byte for byte.
- :func:`load_reference_driver` imports one of Adafruit's driver modules with a fake
  ``busio`` and ``micropython`` in ``sys.modules`` for the length of a test, and its
  ``time`` swapped for :class:`SimulatedTime` (Adafruit-Blinka, which the drivers declare
  as a dependency, is never imported).
"""

from __future__ import annotations

import importlib
import sys
import types
from collections.abc import Sequence

import pytest

from engine.clock import VirtualClock
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.vl53l0x import SimVL53L0X

WriteTransfer = tuple[int, bytes]
"""One write transfer: the 7-bit address and the bytes sent (register pointer first)."""


class TransactionBudgetError(AssertionError):
    """A reference driver kept talking long past any bring-up or reading: it is stuck."""


class RecordingBus(SimI2CBus):
    """A simulated bus that keeps every write transfer in :attr:`writes`, in order."""

    def __init__(self, clock: VirtualClock) -> None:
        super().__init__(clock)
        self.writes: list[WriteTransfer] = []

    def transfer(self, messages: Sequence[tuple[int, bool, bytes | int]]) -> list[bytes]:
        for address, is_read, payload in messages:
            if not is_read:
                self.writes.append((address, bytes(payload)))  # type: ignore[arg-type]
        return super().transfer(messages)

    def register_writes(self, address: int) -> list[WriteTransfer]:
        """Writes to ``address`` that set registers (a pointer byte alone sets none)."""
        return [(a, data) for a, data in self.writes if a == address and len(data) >= 2]


class ReferenceI2C:
    """The ``busio.I2C`` calls Adafruit's drivers make, over a simulated bus."""

    def __init__(
        self,
        bus: SimI2CBus,
        clock: VirtualClock,
        *,
        frequency_hz: int = 100_000,
        max_transactions: int = 20_000,
    ) -> None:
        self._bus = bus
        self._clock = clock
        self.frequency_hz = frequency_hz
        self.max_transactions = max_transactions
        self.transactions = 0

    def try_lock(self) -> bool:
        return True  # one test, one thread: the bus is always free

    def unlock(self) -> None:
        """Nothing to release."""

    def writeto(
        self, address: int, buffer: bytes, *, start: int = 0, end: int | None = None
    ) -> None:
        self._run([(address, False, bytes(buffer[start:end]))])

    def readfrom_into(
        self, address: int, buffer: bytearray, *, start: int = 0, end: int | None = None
    ) -> None:
        stop = len(buffer) if end is None else end
        (data,) = self._run([(address, True, stop - start)])
        buffer[start:stop] = data

    def writeto_then_readfrom(
        self,
        address: int,
        out_buffer: bytes,
        in_buffer: bytearray,
        *,
        out_start: int = 0,
        out_end: int | None = None,
        in_start: int = 0,
        in_end: int | None = None,
    ) -> None:
        stop = len(in_buffer) if in_end is None else in_end
        out = bytes(out_buffer[out_start:out_end])  # copied first: the buffers may be one
        (data,) = self._run([(address, False, out), (address, True, stop - in_start)])
        in_buffer[in_start:stop] = data

    def _run(self, messages: list[tuple[int, bool, bytes | int]]) -> list[bytes]:
        self.transactions += 1
        if self.transactions > self.max_transactions:
            last = messages[0]
            raise TransactionBudgetError(
                f"the reference driver made more than {self.max_transactions} I2C transactions "
                f"(the last one to 0x{last[0]:02X}): it is waiting for something the simulated "
                "chip never does"
            )
        byte_count = sum(1 + (p if isinstance(p, int) else len(p)) for _, _, p in messages)
        self._clock.advance(9 * byte_count / self.frequency_hz)
        return self._bus.transfer(messages)


class SimulatedTime:
    """The ``time`` module as a driver sees it, on the simulated clock."""

    def __init__(self, clock: VirtualClock) -> None:
        self._clock = clock

    def monotonic(self) -> float:
        return self._clock.now()

    def monotonic_ns(self) -> int:
        return round(self._clock.now() * 1e9)

    def sleep(self, seconds: float) -> None:
        self._clock.sleep(seconds)


def circuitpython_modules() -> dict[str, types.ModuleType]:
    """The CircuitPython modules the drivers import, by name: ``busio`` and ``micropython``.

    ``adafruit_bus_device`` imports ``busio.SPI`` for its annotations; no driver here uses it.
    """
    busio = types.ModuleType("busio", "stand-in: I2C over a simulated bus; SPI only named")
    busio.I2C = ReferenceI2C  # type: ignore[attr-defined]
    busio.SPI = type("SPI", (), {"__doc__": "named in annotations only"})  # type: ignore[attr-defined]
    micropython = types.ModuleType("micropython", "stand-in: const() as CPython sees it")
    micropython.const = lambda value: value  # type: ignore[attr-defined]
    return {"busio": busio, "micropython": micropython}


def load_reference_driver(
    name: str, clock: VirtualClock, monkeypatch: pytest.MonkeyPatch
) -> types.ModuleType:
    """Adafruit's driver module ``name``, living on ``clock`` for the length of a test."""
    for module_name, module in circuitpython_modules().items():
        monkeypatch.setitem(sys.modules, module_name, module)
    driver = importlib.import_module(name)
    for module in (driver, *_submodules(driver)):
        if isinstance(getattr(module, "time", None), types.ModuleType):
            monkeypatch.setattr(module, "time", SimulatedTime(clock))
    return driver


def _submodules(package: types.ModuleType) -> list[types.ModuleType]:
    prefix = package.__name__ + "."
    return [m for n, m in sorted(sys.modules.items()) if n.startswith(prefix) and m is not None]


class NvmOff(SimVL53L0X):
    """A simulated VL53L0X whose NVM read strobe never completes (0x83 keeps reading 0):
    the chip Adafruit's driver waits for for ever, and ours gives up on."""

    def _strobe_nvm(self, bank: bytearray) -> None:
        pass
