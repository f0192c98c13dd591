"""What a VL53L0X measurement's result block says: a distance, nothing in range, or a
reading no chip gives (said, never passed on as a distance)."""

from __future__ import annotations

from engine.drivers import vl53l0x_registers as reg
from engine.drivers.device_errors import ImplausibleReadingError

CHIP = "VL53L0X"
DEVICE_RANGE_STATUS_VALID = reg.DEVICE_RANGE_STATUS_VALID
DEVICE_RANGE_STATUS_TOO_CLOSE = frozenset({8, 10})
"""Device range statuses of a target closer than the chip can range ("min range fail")."""
RANGE_OUT_OF_RANGE_MM = reg.RANGE_OUT_OF_RANGE_MM
RANGE_CODE_MAX = 8191  # the range field never holds more
MAX_RANGE_MM = 2000  # the chip's reach (long-range mode); a valid range beyond it is garbled


def device_range_status(status_byte: int) -> int:
    """The device range status (bits 6:3) of RESULT_RANGE_STATUS; 11 is a valid range."""
    return (status_byte >> reg.DEVICE_RANGE_STATUS_SHIFT) & 0x0F


def decode_range(status_byte: int, range_mm: int) -> int | None:
    """The distance in mm, or ``None`` when the chip found nothing valid in range. A
    target too close to range (the device's "min range" statuses, 8 and 10: a hand over
    the sensor) is 0 mm: something is right there, the worst case for whoever relies on
    it."""
    status = device_range_status(status_byte)
    if status in DEVICE_RANGE_STATUS_TOO_CLOSE:
        return 0
    if range_mm >= RANGE_OUT_OF_RANGE_MM:
        return None
    if status != DEVICE_RANGE_STATUS_VALID:
        return None
    return range_mm


def distance_in(result: bytes, place: str) -> int | None:
    """The distance in mm that a result block (``RESULT_BLOCK_LENGTH`` bytes from
    RESULT_RANGE_STATUS) holds, or ``None`` for nothing in range.
    :class:`~engine.drivers.device_errors.ImplausibleReadingError` for a valid range
    beyond the chip's ~2 m, or a range field above 8191 (``place``: where the chip is)."""
    offset = reg.RESULT_RANGE_MM_OFFSET
    range_mm = (result[offset] << 8) | result[offset + 1]
    distance_mm = decode_range(result[0], range_mm)
    if range_mm > RANGE_CODE_MAX or (distance_mm is not None and distance_mm > MAX_RANGE_MM):
        valid = device_range_status(result[0]) == DEVICE_RANGE_STATUS_VALID
        raise ImplausibleReadingError(
            chip=CHIP,
            place=place,
            what="range with a valid status" if valid else "range",
            value=f"{range_mm} mm",
            plausible=f"0..{MAX_RANGE_MM} mm, or {RANGE_OUT_OF_RANGE_MM}..{RANGE_CODE_MAX} "
            "for nothing in range",
        )
    return distance_mm
