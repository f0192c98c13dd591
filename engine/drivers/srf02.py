"""Driver for the Devantech SRF02 ultrasonic range finder in I2C mode (default 0x70).

The vest asks it for the far range on request. A ranging is commanded by writing 0x51
(result in cm) to the command register (0); it lasts up to about 66 ms, during which the
chip does not listen and the software revision register (0) reads 0xFF. The result is
the 16-bit unsigned pair at registers 2 (high) and 3 (low).

What the numbers mean:

- 0 cm: no echo, nothing within the sensor's ~6 m.
- The chip cannot see closer than its minimum range (the transducer still rings after
  the burst): about 16 cm once its autotune has settled, 28 cm for the first few rangings
  after power-up. An object closer than that reads as the minimum, never less; treat a
  reading at or below :data:`MIN_RANGE_CM` as "this close or closer".

:meth:`read_range_cm` blocks for a ranging on the injected clock; a service that must not
block calls :meth:`start_ranging`, then :meth:`result_ready` on later ticks and
:meth:`read_result_cm` once it is.
"""

from __future__ import annotations

from engine.clock import Clock
from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, i2c_place, not_found
from engine.drivers.srf02_registers import (
    BUSY,
    COMMAND,
    MAX_RANGE_CM,
    RANGE_CM,
    RANGE_HIGH,
    RANGING_TIME_S,
    TUNED_MIN_CM,
    UNUSED,
    UNUSED_VALUE,
)
from engine.errors import DeviceError

POLL_INTERVAL_S = 0.005
MAX_POLLS = 10
MIN_RANGE_CM = round(TUNED_MIN_CM)  # a fresh chip starts at POWER_UP_MIN_CM
PLAUSIBLE_MIN_CM = 15  # below its minimum range the chip reports the minimum, never less


class SRF02:
    """An SRF02 on an ``smbus2.SMBus``-compatible ``bus``, timed by ``clock``.

    Construction checks that the chip answers a software revision (not 0xFF) and reads
    0x80 in its unused register; :class:`DeviceError` names chip and address otherwise.
    """

    def __init__(
        self,
        bus: I2CBus,
        *,
        address: int = 0x70,
        clock: Clock,
        max_polls: int = MAX_POLLS,
        poll_interval_s: float = POLL_INTERVAL_S,
    ) -> None:
        if max_polls < 1:
            raise ValueError(f"SRF02 max_polls {max_polls} must be at least 1")
        if not poll_interval_s > 0:
            raise ValueError(f"SRF02 poll interval {poll_interval_s} s must be positive")
        self._bus = bus
        self.address = address
        self._clock = clock
        self._max_polls = max_polls
        self._poll_interval_s = poll_interval_s
        self._started_s: float | None = None
        self.software_revision = self._check_identity()

    # -- non-blocking use ---------------------------------------------------------------
    def start_ranging(self) -> None:
        """Command a ranging in cm; the result is ready about 66 ms later."""
        self._bus.write_byte_data(self.address, COMMAND, RANGE_CM)
        self._started_s = self._clock.now()

    def result_ready(self) -> bool:
        """True once the last ranging finished (no bus traffic before 66 ms have passed).

        The chip does not listen while ranging: the revision register reads 0xFF, or on
        a bus that checks acknowledges the read fails. A failed read counts as "not yet"
        until the polling allowance (``max_polls`` x ``poll_interval_s`` after the
        ranging time) has passed, and is raised after that.
        """
        if self._started_s is None:
            return True
        now = self._clock.now()
        if now < self._started_s + RANGING_TIME_S:
            return False
        try:
            busy = self._read(COMMAND, 1)[0] == BUSY
        except OSError:
            allowance_s = RANGING_TIME_S + self._max_polls * self._poll_interval_s
            if now < self._started_s + allowance_s:
                return False
            raise
        if busy:
            return False
        self._started_s = None
        return True

    def read_result_cm(self) -> int:
        """The latest result in cm (0: nothing in range); ``DeviceError`` while ranging.

        A result the chip cannot report (between 1 and 14 cm, or beyond 600 cm) raises
        :class:`~engine.drivers.device_errors.ImplausibleReadingError`.
        """
        if not self.result_ready():
            raise DeviceError(
                f"SRF02 at I2C 0x{self.address:02X} is still ranging; "
                "wait for result_ready() before reading the result"
            )
        high, low = self._read(RANGE_HIGH, 2)
        range_cm = high << 8 | low
        if range_cm != 0 and not PLAUSIBLE_MIN_CM <= range_cm <= MAX_RANGE_CM:
            raise ImplausibleReadingError(
                chip="SRF02",
                place=i2c_place(self.address),
                what="range",
                value=f"{range_cm} cm",
                plausible=f"0 for no echo, or {PLAUSIBLE_MIN_CM}..{MAX_RANGE_CM} cm",
            )
        return range_cm

    # -- blocking use -------------------------------------------------------------------
    def read_range_cm(self) -> int:
        """Range once and return the distance in cm (0: nothing in range).

        Waits the ranging time on the clock, then polls the revision register at most
        ``max_polls`` times; ``DeviceError`` if the chip is still busy after that.
        """
        self.start_ranging()
        assert self._started_s is not None
        self._clock.sleep_until(self._started_s + RANGING_TIME_S)
        for _ in range(self._max_polls):
            if self.result_ready():
                return self.read_result_cm()
            self._clock.sleep(self._poll_interval_s)
        raise DeviceError(
            f"SRF02 at I2C 0x{self.address:02X} still ranging after "
            f"{RANGING_TIME_S + self._max_polls * self._poll_interval_s:.3f} s"
        )

    # -- helpers ------------------------------------------------------------------------
    def _check_identity(self) -> int:
        try:
            revision = self._read(COMMAND, 1)[0]
            if revision == BUSY:  # perhaps mid-ranging from an earlier command
                self._clock.sleep(RANGING_TIME_S)
                revision = self._read(COMMAND, 1)[0]
            unused = self._read(UNUSED, 1)[0]
        except DeviceError:
            raise
        except OSError as error:
            raise not_found("SRF02", self.address, error) from error
        if revision == BUSY or unused != UNUSED_VALUE:
            raise DeviceError(
                f"SRF02 at I2C 0x{self.address:02X} failed its identity check: software "
                f"revision reads 0x{revision:02X} (0xFF means busy or absent) and register 1 "
                f"reads 0x{unused:02X} (expected 0x{UNUSED_VALUE:02X})"
            )
        return revision

    def _read(self, register: int, length: int) -> list[int]:
        return list(self._bus.read_i2c_block_data(self.address, register, length))
