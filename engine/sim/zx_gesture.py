"""A register-level model of the XYZ Interactive ZX Sensor (I2C register map v1).

What it models: MODEL (0xFF) = 0x01 and REGVER (0xFE) = 0x01; STATUS (0x00) with DAV for a
new coordinate, SWP / HOVER / HVG for a swipe / hover / hover-move gesture, all cleared by
reading STATUS, and the heartbeat bit 7 toggling on each STATUS read; GESTURE (0x04) and
GSPEED (0x05) keeping the last gesture until the next one; XPOS (0x08) and ZPOS (0x0A)
keeping the last coordinate; DRE (0x01) and DRCFG (0x02, FORCE bit self-clearing)
writable, every other register read-only; a register pointer that auto-increments.

While a hand is in view the chip produces a new coordinate every ``sample_period_s``
(DAV set again each time); when it leaves, DAV stays clear and X/Z keep their last values.

Simplified: the coordinate rate is a stand-in (the register map does not state it), the
ranging registers LRNG/RRNG are derived from Z crudely, the DR pin is not modelled, and
gestures are performed on request rather than recognised from hand motion.
"""

from __future__ import annotations

from engine.clock import Clock
from engine.drivers.zx_gesture_registers import (
    ADDRESSES,
    DRCFG,
    DRCFG_FORCE,
    DRCFG_POWER_ON,
    DRE,
    GESTURE,
    GESTURES,
    GSPEED,
    LRNG,
    MAX_POSITION,
    MODEL,
    MODEL_ID,
    REGISTER_MAP_VERSION,
    REGVER,
    RRNG,
    STATUS,
    STATUS_DAV,
    STATUS_HB,
    XPOS,
    ZPOS,
)
from engine.sim.i2c_bus import SimI2CDevice


class SimZXGesture(SimI2CDevice):
    """A ZX sensor in front of which a simulated hand moves and gestures."""

    def __init__(
        self,
        clock: Clock,
        address: int = 0x10,
        *,
        sample_period_s: float = 0.02,
        model: int = MODEL_ID,
        register_map_version: int = REGISTER_MAP_VERSION,
    ) -> None:
        if address not in ADDRESSES:
            raise ValueError(f"a ZX sensor answers on 0x10 or 0x11, not 0x{address:02X}")
        super().__init__(address)
        self._clock = clock
        self.sample_period_s = sample_period_s
        self._registers = bytearray(256)
        self._registers[DRCFG] = DRCFG_POWER_ON
        self._registers[REGVER] = register_map_version
        self._registers[MODEL] = model
        self._pointer = 0
        self._flags = 0
        self._heartbeat = 0
        self._hand_since_s: float | None = None
        self._sample_index = 0

    # -- the world ---------------------------------------------------------------------------
    def perform(self, gesture: str, *, speed: int = 10) -> None:
        """A hand makes ``gesture`` (e.g. ``swipe_left``, ``hover``) at ``speed`` (0..255)."""
        if gesture not in GESTURES:
            known = ", ".join(GESTURES)
            raise ValueError(f"the ZX sensor knows no gesture {gesture!r}; it knows {known}")
        if not 0 <= speed <= 255:
            raise ValueError(f"gesture speed must be 0..255, got {speed}")
        code, flag = GESTURES[gesture]
        self._registers[GESTURE] = code
        self._registers[GSPEED] = speed
        self._flags |= flag

    def hand_at(self, x: int, z: int) -> None:
        """Put a hand at ``x`` (across, 0..240) and ``z`` (away, 0..240) in sensor units."""
        for name, value in (("x", x), ("z", z)):
            if not 0 <= value <= MAX_POSITION:
                raise ValueError(f"ZX {name} position must be 0..{MAX_POSITION}, got {value}")
        self._tick()
        if self._hand_since_s is None:
            self._hand_since_s = self._clock.now()
            self._sample_index = 0
        self._registers[XPOS] = x
        self._registers[ZPOS] = z
        self._registers[LRNG] = self._registers[RRNG] = MAX_POSITION - z
        self._flags |= STATUS_DAV

    def hand_away(self) -> None:
        """The hand leaves: no new coordinates; X and Z keep their last values."""
        self._tick()
        self._hand_since_s = None

    def _tick(self) -> None:
        """A new coordinate every sample period while a hand is in view."""
        if self._hand_since_s is None:
            return
        index = int((self._clock.now() - self._hand_since_s) // self.sample_period_s)
        if index > self._sample_index:
            self._sample_index = index
            self._flags |= STATUS_DAV

    # -- the wire ------------------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if not data:
            return
        self._pointer = data[0]
        for value in data[1:]:
            if self._pointer == DRE:
                self._registers[DRE] = value & 0x3F
            elif self._pointer == DRCFG:
                self._registers[DRCFG] = value & ~DRCFG_FORCE  # FORCE clears itself
            self._pointer = (self._pointer + 1) & 0xFF

    def read(self, length: int) -> bytes:
        out = bytearray()
        for _ in range(length):
            if self._pointer == STATUS:
                out.append(self._read_status())
            else:
                out.append(self._registers[self._pointer])
            self._pointer = (self._pointer + 1) & 0xFF
        return bytes(out)

    def _read_status(self) -> int:
        self._tick()
        status = self._flags | self._heartbeat
        self._flags = 0  # every flag clears on read
        self._heartbeat ^= STATUS_HB
        return status
