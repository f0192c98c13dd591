"""Driver for the NXP MPR121 12-pad capacitive touch controller (I2C, default 0x5A).

The vest's back and shoulder pads hang off one MPR121; the engine polls :meth:`touched`.

Start-up follows the data sheet: a soft reset (0x63 to register 0x80) puts every register
at its default, which doubles as the identity check (CONFIG2, 0x5D, must then read 0x24);
the chip is put in stop mode (ECR 0x5E = 0) because it ignores configuration writes while
it runs; thresholds, baseline filters, debounce and the analog front end are written; and
ECR finally enables the 12 electrodes with baseline tracking whose initial value is loaded
from the first reading.

Thresholds are in counts of the chip's 10-bit electrode data: a pad is touched when its
baseline minus its filtered data exceeds the touch threshold and released when that
difference falls below the release threshold (hysteresis).
"""

from __future__ import annotations

from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, i2c_place, not_found
from engine.drivers.mpr121_registers import (
    BASELINE_0,
    CONFIG1,
    CONFIG2,
    CONFIG2_DEFAULT,
    DEBOUNCE,
    ECR,
    ECR_CL_LOAD_5_MSB,
    ECR_STOP,
    FILTERED_DATA_0,
    MHD_RISING,
    PADS,
    SOFT_RESET,
    SOFT_RESET_MAGIC,
    STATUS_NOT_PADS_MASK,
    TOUCH_STATUS_L,
    TOUCH_THRESHOLD_0,
)
from engine.errors import DeviceError

ECR_RUN_12_PADS = ECR_CL_LOAD_5_MSB | 12

# Baseline filter, rising (MHD, NHD, NCL, FDL), falling (same) and touched (NHD, NCL,
# FDL): the usual starting values of the reference drivers, written from 0x2B onwards.
BASELINE_FILTER = (0x01, 0x01, 0x0E, 0x00, 0x01, 0x05, 0x01, 0x00, 0x00, 0x00, 0x00)
CONFIG1_16UA = 0x10  # 6 first-filter samples, 16 uA charge current
CONFIG2_HALF_US_1MS = 0x20  # 0.5 us charge time, 4 second-filter samples, 1 ms period


def _check_threshold(name: str, value: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 255:
        raise ValueError(f"MPR121 {name} threshold {value!r} is not a count in 0..255")


def check_thresholds(touch: int, release: int) -> None:
    """Raise ``ValueError`` unless ``0 <= release <= touch <= 255`` (counts) and touch > 0."""
    _check_threshold("touch", touch)
    _check_threshold("release", release)
    if touch == 0:
        raise ValueError("MPR121 touch threshold 0 would report every pad as touched")
    if release > touch:
        raise ValueError(
            f"MPR121 release threshold {release} is above the touch threshold {touch}; "
            "release must be at most touch (hysteresis)"
        )


def status_to_pads(status: int) -> list[bool]:
    """The 16-bit touch status word as 12 booleans, pad 0 first."""
    return [bool(status >> pad & 1) for pad in range(PADS)]


class MPR121:
    """An MPR121 on an ``smbus2.SMBus``-compatible ``bus``.

    Construction resets, identifies and starts the chip; :class:`DeviceError` names chip
    and address when nothing answers or something else does.
    """

    def __init__(
        self,
        bus: I2CBus,
        *,
        address: int = 0x5A,
        touch_threshold: int = 12,
        release_threshold: int = 6,
    ) -> None:
        check_thresholds(touch_threshold, release_threshold)
        self._bus = bus
        self.address = address
        self._touch_threshold = touch_threshold
        self._release_threshold = release_threshold
        self.reset()

    @property
    def touch_threshold(self) -> int:
        """Touch threshold in counts of electrode data."""
        return self._touch_threshold

    @property
    def release_threshold(self) -> int:
        """Release threshold in counts of electrode data."""
        return self._release_threshold

    def reset(self) -> None:
        """Soft-reset, check identity, configure in stop mode, then run all 12 pads."""
        try:
            self._write(SOFT_RESET, SOFT_RESET_MAGIC)
            config2 = self._read(CONFIG2, 1)[0]
        except DeviceError:
            raise
        except OSError as error:
            raise not_found("MPR121", self.address, error) from error
        if config2 != CONFIG2_DEFAULT:
            raise DeviceError(
                f"MPR121 at I2C 0x{self.address:02X} failed its identity check: CONFIG2 "
                f"(0x{CONFIG2:02X}) reads 0x{config2:02X} after a soft reset, expected "
                f"0x{CONFIG2_DEFAULT:02X}; is another chip at this address?"
            )
        self._write(ECR, ECR_STOP)  # the chip ignores configuration writes while running
        self._write_thresholds(self._touch_threshold, self._release_threshold)
        self._bus.write_i2c_block_data(self.address, MHD_RISING, list(BASELINE_FILTER))
        self._write(DEBOUNCE, 0)
        self._write(CONFIG1, CONFIG1_16UA)
        self._write(CONFIG2, CONFIG2_HALF_US_1MS)
        self._write(ECR, ECR_RUN_12_PADS)

    def touched(self) -> list[bool]:
        """Which of the 12 pads are touched now, pad 0 first.

        A status with a bit set above the pads (proximity, reserved, over-current) raises
        :class:`~engine.drivers.device_errors.ImplausibleReadingError`.
        """
        low, high = self._read(TOUCH_STATUS_L, 2)
        status = low | high << 8
        if status & STATUS_NOT_PADS_MASK:
            raise ImplausibleReadingError(
                chip="MPR121",
                place=i2c_place(self.address),
                what="touch status",
                value=f"0x{status:04X}",
                plausible="bits 12..15 clear: proximity off, no over-current",
            )
        return status_to_pads(status)

    def set_thresholds(self, touch: int, release: int) -> None:
        """Set the touch and release thresholds (counts) of every pad.

        The chip ignores threshold writes in run mode, so it is stopped around the write
        and restarted with its previous electrode configuration (baselines reload).
        """
        check_thresholds(touch, release)
        ecr = self._read(ECR, 1)[0]
        self._write(ECR, ECR_STOP)
        self._write_thresholds(touch, release)
        self._write(ECR, ecr)
        self._touch_threshold = touch
        self._release_threshold = release

    def filtered_data(self, pad: int) -> int:
        """The pad's 10-bit filtered electrode data, in counts (for tuning thresholds)."""
        self._check_pad(pad)
        low, high = self._read(FILTERED_DATA_0 + 2 * pad, 2)
        return (low | high << 8) & 0x3FF

    def baseline_data(self, pad: int) -> int:
        """The pad's baseline in counts (10-bit, the chip keeps only its upper 8 bits)."""
        self._check_pad(pad)
        return self._read(BASELINE_0 + pad, 1)[0] << 2

    # -- helpers ------------------------------------------------------------------------
    @staticmethod
    def _check_pad(pad: int) -> None:
        if not 0 <= pad < PADS:
            raise ValueError(f"MPR121 pad {pad} is outside 0..{PADS - 1}")

    def _write_thresholds(self, touch: int, release: int) -> None:
        # One auto-incrementing block write: touch, release for ELE0, then ELE1...
        self._bus.write_i2c_block_data(self.address, TOUCH_THRESHOLD_0, [touch, release] * PADS)

    def _write(self, register: int, value: int) -> None:
        self._bus.write_byte_data(self.address, register, value)

    def _read(self, register: int, length: int) -> list[int]:
        return list(self._bus.read_i2c_block_data(self.address, register, length))
