"""NXP PCA9685 16-channel, 12-bit PWM controller (I2C, default address 0x40).

Each channel n has four registers from LEDn_ON_L = 0x06 + 4 n: a 12-bit ON count and a
12-bit OFF count (little-endian: low byte first), plus a "full on" bit (bit 4 of ON_H) and
a "full off" bit (bit 4 of OFF_H, which wins over full on). One PWM period is 4096 counts
of the prescaled oscillator: ``f = oscillator / (4096 * (PRE_SCALE + 1))``.

PRE_SCALE can only be written while MODE1.SLEEP is set; leaving sleep, the oscillator needs
500 us before the RESTART bit may restart the channels that were running. The chip has no
identity register; construction checks that it answers and that PRE_SCALE holds at least
3, the hardware minimum.
"""

from __future__ import annotations

import threading

from engine.clock import Clock
from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, device_error, i2c_place
from engine.drivers.pca9685_registers import (
    ALL_LED_OFF_H,
    CHANNELS,
    COUNTS,
    FULL,
    LED0_ON_L,
    LED_STRIDE,
    MODE1,
    MODE1_AI,
    MODE1_RESTART,
    MODE1_SLEEP,
    MODE2,
    MODE2_OUTDRV,
    OSCILLATOR_WAKE_S,
    PRE_SCALE,
    PRESCALE_MAX,
    PRESCALE_MIN,
)
from engine.errors import DeviceError

CHIP = "PCA9685"


# -- pure conversions ---------------------------------------------------------------------------
def frequency_range_hz(oscillator_hz: float = 25e6) -> tuple[float, float]:
    """The lowest and highest PWM frequency in Hz, rounded to whole Hz (24..1526 at 25 MHz)."""
    low = oscillator_hz / (COUNTS * (PRESCALE_MAX + 1))
    high = oscillator_hz / (COUNTS * (PRESCALE_MIN + 1))
    return float(round(low)), float(round(high))


def prescale_for(frequency_hz: float, oscillator_hz: float = 25e6) -> int:
    """The PRE_SCALE value for ``frequency_hz``: round(osc / (4096 f)) - 1 (datasheet eq. 1)."""
    low, high = frequency_range_hz(oscillator_hz)
    if not low <= frequency_hz <= high:
        raise ValueError(
            f"{CHIP} PWM frequency must be {low:g}..{high:g} Hz with a "
            f"{oscillator_hz / 1e6:g} MHz oscillator, got {frequency_hz} Hz"
        )
    prescale = round(oscillator_hz / (COUNTS * frequency_hz)) - 1
    return min(max(prescale, PRESCALE_MIN), PRESCALE_MAX)


def frequency_for(prescale: int, oscillator_hz: float = 25e6) -> float:
    """The PWM frequency in Hz that a PRE_SCALE value gives."""
    return oscillator_hz / (COUNTS * (prescale + 1))


def duty_to_counts(fraction: float) -> tuple[int, int]:
    """A duty cycle (0.0..1.0) as the 16-bit (ON, OFF) register values of one channel.

    0.0 and anything rounding to no count is "full off"; 1.0 and anything rounding to a
    whole period is "full on"; otherwise the output turns on at count 0 and off at
    ``round(fraction * 4096)``.
    """
    if not 0.0 <= fraction <= 1.0:  # also rejects NaN
        raise ValueError(f"{CHIP} duty cycle must be 0.0..1.0, got {fraction}")
    counts = round(fraction * COUNTS)
    if counts <= 0:
        return 0, FULL
    if counts >= COUNTS:
        return FULL, 0
    return 0, counts


def counts_to_duty(on: int, off: int) -> float:
    """The duty cycle (0.0..1.0) that 16-bit ON and OFF register values give."""
    if off & FULL:
        return 0.0
    if on & FULL:
        return 1.0
    return ((off - on) % COUNTS) / COUNTS


def _check_channel(channel: int) -> None:
    if not 0 <= channel < CHANNELS:
        raise ValueError(f"{CHIP} channel must be 0..{CHANNELS - 1}, got {channel}")


class PCA9685:
    """A PCA9685, reset on construction: outputs off, auto-increment on, All Call off,
    oscillator running.

    The PWM frequency is left as the chip holds it (200 Hz after power-on) until
    :meth:`set_frequency_hz`. Thread-safe.
    """

    def __init__(
        self,
        bus: I2CBus,
        *,
        address: int = 0x40,
        clock: Clock,
        oscillator_hz: float = 25e6,
    ) -> None:
        if not 0x40 <= address <= 0x77 or address == 0x70:
            # 0x70 is the chip's LED All Call address, answered by every PCA9685 by default.
            raise ValueError(f"{CHIP} address must be 0x40..0x77 except 0x70, got 0x{address:02X}")
        if not 0 < oscillator_hz <= 50e6:
            raise ValueError(f"{CHIP} oscillator must be up to 50 MHz, got {oscillator_hz} Hz")
        self._bus = bus
        self.address = address
        self._clock = clock
        self.oscillator_hz = oscillator_hz
        self._lock = threading.Lock()
        where = f"{CHIP} at 0x{address:02X}"
        try:
            prescale = bus.read_byte_data(address, PRE_SCALE)
        except OSError as err:
            raise device_error(f"{where} did not answer: {err.strerror or err}", err) from err
        if prescale < PRESCALE_MIN:
            raise DeviceError(
                f"{where}: PRE_SCALE reads {prescale}, below the chip's hardware minimum "
                f"{PRESCALE_MIN}: not a PCA9685"
            )
        with self._lock:
            # Orderly shutdown first, so no channel is left to restart from an earlier run.
            bus.write_byte_data(address, ALL_LED_OFF_H, FULL >> 8)
            bus.write_byte_data(address, MODE2, MODE2_OUTDRV)
            # ALLCALL off: the chip would otherwise also take writes to 0x70, the SRF02's
            # address (an SRF02 command would land in MODE1 and could set EXTCLK for good).
            bus.write_byte_data(address, MODE1, MODE1_AI)
            clock.sleep(OSCILLATOR_WAKE_S)

    def __repr__(self) -> str:
        return f"PCA9685(address=0x{self.address:02X})"

    def _read(self, register: int) -> int:
        return self._bus.read_byte_data(self.address, register)

    def _write(self, register: int, value: int) -> None:
        self._bus.write_byte_data(self.address, register, value)

    @property
    def frequency_hz(self) -> float:
        """The PWM frequency in Hz, from the chip's PRE_SCALE register."""
        with self._lock:
            prescale = self._read(PRE_SCALE)
        if prescale < PRESCALE_MIN:  # the chip holds at least 3 whatever is written
            raise ImplausibleReadingError(
                chip=CHIP,
                place=i2c_place(self.address),
                what="PRE_SCALE",
                value=str(prescale),
                plausible=f"{PRESCALE_MIN}..{PRESCALE_MAX}",
            )
        return frequency_for(prescale, self.oscillator_hz)

    def set_frequency_hz(self, frequency_hz: float) -> None:
        """Set the PWM frequency of every channel (24..1526 Hz with the 25 MHz oscillator).

        PRE_SCALE is writable only asleep: sleep, write it, restore MODE1, wait 500 us for
        the oscillator, then restart the channels that were running.
        """
        prescale = prescale_for(frequency_hz, self.oscillator_hz)
        with self._lock:
            mode1 = self._read(MODE1) & ~MODE1_RESTART  # writing RESTART=1 would act on it
            self._write(MODE1, mode1 | MODE1_SLEEP)
            self._write(PRE_SCALE, prescale)
            self._write(MODE1, mode1)
            if mode1 & MODE1_SLEEP:
                return  # it was asleep before: leave it so
            self._clock.sleep(OSCILLATOR_WAKE_S)
            if self._read(MODE1) & MODE1_RESTART:
                self._write(MODE1, mode1 | MODE1_RESTART)

    def set_duty(self, channel: int, fraction: float) -> None:
        """Set one channel's duty cycle (0.0 = always off .. 1.0 = always on)."""
        _check_channel(channel)
        on, off = duty_to_counts(fraction)
        block = [on & 0xFF, on >> 8, off & 0xFF, off >> 8]
        with self._lock:
            self._bus.write_i2c_block_data(self.address, LED0_ON_L + LED_STRIDE * channel, block)

    def duty(self, channel: int) -> float:
        """One channel's duty cycle as the chip's registers hold it (0.0..1.0)."""
        _check_channel(channel)
        with self._lock:
            on_l, on_h, off_l, off_h = self._bus.read_i2c_block_data(
                self.address, LED0_ON_L + LED_STRIDE * channel, 4
            )
        return counts_to_duty(on_l | (on_h << 8), off_l | (off_h << 8))

    def all_off(self) -> None:
        """Every channel full off, in one register write."""
        with self._lock:
            self._write(ALL_LED_OFF_H, FULL >> 8)
