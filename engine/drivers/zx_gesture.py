"""XYZ Interactive ZX Sensor (SparkFun ZX Distance and Gesture Sensor), I2C register map v1.

Address 0x10 (0x11 with the address jumper closed). The chip reports swipes and hovers
through GESTURE (0x04) and flags them in STATUS (0x00); it reports the hand's position as
X (0x08, across the sensor, 0..240) and Z (0x0A, away from it, 0..240) and flags each new
coordinate with STATUS.DAV. Every flag in STATUS clears when STATUS is read, so this driver
keeps the flags it has seen but not yet consumed: reading the position never loses a
gesture, and each gesture is reported once. A new driver reads STATUS once and discards it:
a gesture the chip latched before (while nobody read it: the bus was down, the robot was
starting) is stale, and must not set off a greeting seconds after the hand went.

The engine calls a left or right swipe a "wave": that mapping belongs to the behaviour
tree; this driver reports what the chip reports.
"""

from __future__ import annotations

import threading

from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, device_error, i2c_place
from engine.drivers.zx_gesture_registers import (
    ADDRESSES,
    DRE,
    GESTURE,
    GESTURES,
    MAX_POSITION,
    MODEL,
    MODEL_ID,
    REGISTER_MAP_VERSION,
    REGVER,
    STATUS,
    STATUS_DAV,
    STATUS_GESTURES,
    XPOS,
    ZPOS,
)
from engine.errors import DeviceError

CHIP = "ZX gesture sensor"

# GESTURE register value -> the engine's gesture name.
GESTURE_NAMES = {code: name for name, (code, _) in GESTURES.items()}


def gesture_name(code: int) -> str | None:
    """The engine's name for a GESTURE register value, or ``None`` for no/unknown gesture."""
    return GESTURE_NAMES.get(code)


def decode_position(x: int, z: int) -> tuple[int, int] | None:
    """X and Z in sensor units (0..240), or ``None`` when either is out of the chip's range."""
    if x > MAX_POSITION or z > MAX_POSITION:
        return None
    return (x, z)


class ZXGesture:
    """A ZX sensor, polled (its DR pin is not used). Thread-safe."""

    def __init__(self, bus: I2CBus, *, address: int = 0x10) -> None:
        if address not in ADDRESSES:
            raise ValueError(f"{CHIP} address must be 0x10 or 0x11, got 0x{address:02X}")
        self._bus = bus
        self.address = address
        self._lock = threading.Lock()
        self._pending = 0
        where = f"{CHIP} at 0x{address:02X}"
        try:
            model = bus.read_byte_data(address, MODEL)
            version = bus.read_byte_data(address, REGVER)
        except OSError as err:
            raise device_error(f"{where} did not answer: {err.strerror or err}", err) from err
        if model != MODEL_ID or version != REGISTER_MAP_VERSION:
            raise DeviceError(
                f"{where}: model 0x{model:02X}, register map 0x{version:02X}; expected "
                f"model 0x{MODEL_ID:02X} with register map 0x{REGISTER_MAP_VERSION:02X}"
            )
        bus.write_byte_data(address, DRE, 0x00)  # polled: the DR pin stays quiet
        bus.read_byte_data(address, STATUS)  # clears what was latched before: stale

    def __repr__(self) -> str:
        return f"ZXGesture(address=0x{self.address:02X})"

    def _poll_status(self) -> None:
        status = self._bus.read_byte_data(self.address, STATUS)
        self._pending |= status & (STATUS_DAV | STATUS_GESTURES)

    def read_gesture(self) -> str | None:
        """The gesture detected since the last call (each is reported once), or ``None``.

        One of ``swipe_right``, ``swipe_left``, ``swipe_up``, ``hover``, ``hover_left``,
        ``hover_right``, ``hover_up``; a code that is none of them raises
        :class:`~engine.drivers.device_errors.ImplausibleReadingError` (no phantom gestures).
        """
        with self._lock:
            self._poll_status()
            if not self._pending & STATUS_GESTURES:
                return None
            self._pending &= ~STATUS_GESTURES
            code = self._bus.read_byte_data(self.address, GESTURE)
        name = gesture_name(code)
        if name is None:  # STATUS announced a gesture: the code must name one
            raise ImplausibleReadingError(
                chip=CHIP,
                place=i2c_place(self.address),
                what="gesture code",
                value=f"0x{code:02X}",
                plausible=", ".join(f"0x{known:02X}" for known in GESTURE_NAMES),
            )
        return name

    def read_position(self) -> tuple[int, int] | None:
        """The hand's (x, z) in sensor units 0..240 when the chip has a new coordinate.

        ``None`` when no new coordinate arrived since the last call (no hand in view).
        A coordinate beyond 240 raises
        :class:`~engine.drivers.device_errors.ImplausibleReadingError`.
        """
        with self._lock:
            self._poll_status()
            if not self._pending & STATUS_DAV:
                return None
            self._pending &= ~STATUS_DAV
            x = self._bus.read_byte_data(self.address, XPOS)
            z = self._bus.read_byte_data(self.address, ZPOS)
        position = decode_position(x, z)
        if position is None:
            raise ImplausibleReadingError(
                chip=CHIP,
                place=i2c_place(self.address),
                what="hand position (x, z)",
                value=f"({x}, {z})",
                plausible=f"0..{MAX_POSITION} each",
            )
        return position
