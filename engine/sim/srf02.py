"""A register-level model of the Devantech SRF02 ultrasonic range finder in I2C mode.

What it models, after the SRF02 technical specification (I2C mode):

- Six registers behind a pointer that auto-increments like a 24xx EEPROM's: 0 reads the
  software revision and takes commands when written, 1 is unused and reads 0x80, 2/3 are
  the latest result (high byte first, unsigned), 4/5 the autotune minimum in the same
  units. Only location 0 can be written.
- Ranging commands 0x50 (inches), 0x51 (cm) and 0x52 (microseconds of flight). A ranging
  lasts 66 ms of clock time; meanwhile register 0 reads 0xFF, the result registers keep
  the previous result and commands are ignored (the chip does not listen while ranging).
- A result of 0 means no echo: nothing within the 6 m range (``distance_cm`` None or
  beyond 600 cm).
- Minimum range: the transducer still rings just after the burst, so the chip cannot see
  closer than its autotuned minimum and reports that minimum for closer objects. The
  minimum starts at 28 cm at power-up and tunes down to 16 cm over the first six
  rangings; command 0x60 restarts the tuning.

What it simplifies: the distance is taken at the start of the ranging (the sound takes
under 35 ms to come back from 6 m), echoes are perfect (no beam width, no multiple or
missed echoes), fake ranging (0x56..0x58) answers 0 as no other sonar fires, the burst
command (0x5C) only makes the chip busy, and the address-change sequence (0xA0, 0xAA,
0xA5, new address) is ignored.
"""

from __future__ import annotations

from engine.clock import Clock
from engine.drivers.srf02_registers import (
    AUTOTUNE_MIN_HIGH,
    AUTOTUNE_MIN_LOW,
    BURST,
    BUSY,
    COMMAND,
    FAKE_RANGE_FIRST,
    FAKE_RANGE_LAST,
    MAX_RANGE_CM,
    POWER_UP_MIN_CM,
    RANGE_CM,
    RANGE_HIGH,
    RANGE_INCHES,
    RANGE_LOW,
    RANGE_MICROSECONDS,
    RANGING_TIME_S,
    RESTART_AUTOTUNE,
    TUNED_MIN_CM,
    UNUSED,
    UNUSED_VALUE,
)
from engine.sim.i2c_bus import SimI2CDevice

TUNING_STEP_CM = 2.0  # per ranging: 28 cm to 16 cm in six rangings
MICROSECONDS_PER_CM = 58.3  # out and back at 343 m/s
CM_PER_INCH = 2.54


def in_units(distance_cm: float, command: int) -> int:
    """A distance as the chip reports it for a ranging ``command``, rounded."""
    if command == RANGE_INCHES:
        return round(distance_cm / CM_PER_INCH)
    if command == RANGE_MICROSECONDS:
        return round(distance_cm * MICROSECONDS_PER_CM)
    return round(distance_cm)


class SimSRF02(SimI2CDevice):
    """An SRF02 facing an object ``distance_cm`` away (``None``: nothing in range).

    ``ranging_time_s`` is how long a ranging keeps the chip busy (66 ms on a healthy one).
    """

    def __init__(
        self,
        clock: Clock,
        address: int = 0x70,
        *,
        software_revision: int = 6,
        ranging_time_s: float = RANGING_TIME_S,
    ) -> None:
        super().__init__(address)
        if not 0 <= software_revision < BUSY:
            raise ValueError(f"SRF02 software revision {software_revision} is outside 0..254")
        if not ranging_time_s > 0:
            raise ValueError(f"SRF02 ranging time {ranging_time_s} s must be positive")
        self._clock = clock
        self._ranging_time_s = ranging_time_s
        self._software_revision = software_revision
        self._distance_cm: float | None = None
        self._pointer = 0
        self._result = 0
        self._minimum_result = 0
        self._rangings = 0
        self._busy_until_s: float | None = None
        self._pending: tuple[int, int] | None = None

    # -- physical side ------------------------------------------------------------------
    @property
    def distance_cm(self) -> float | None:
        """Distance to the nearest object in the beam, cm; ``None`` when there is none."""
        return self._distance_cm

    @distance_cm.setter
    def distance_cm(self, value: float | None) -> None:
        if value is not None and not value >= 0:
            raise ValueError(f"SRF02 distance {value} cm must be non-negative or None")
        self._distance_cm = value

    @property
    def minimum_range_cm(self) -> float:
        """The closest distance the chip can see now (autotune), cm."""
        return max(TUNED_MIN_CM, POWER_UP_MIN_CM - TUNING_STEP_CM * self._rangings)

    @property
    def ranging(self) -> bool:
        """True while a ranging is under way."""
        self._update()
        return self._busy_until_s is not None

    # -- wire side ----------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if not data:
            return
        self._update()
        self._pointer = data[0]
        if len(data) > 1 and self._pointer == COMMAND and self._busy_until_s is None:
            self._command(data[1])
        if len(data) > 1:
            self._pointer = (self._pointer + len(data) - 1) & 0xFF

    def read(self, length: int) -> bytes:
        self._update()
        out = bytearray()
        for _ in range(length):
            out.append(self._read_register(self._pointer))
            self._pointer = (self._pointer + 1) & 0xFF
        return bytes(out)

    # -- chip internals -----------------------------------------------------------------
    def _read_register(self, register: int) -> int:
        if register == COMMAND:
            return BUSY if self._busy_until_s is not None else self._software_revision
        if register == UNUSED:
            return UNUSED_VALUE
        if register == RANGE_HIGH:
            return self._result >> 8
        if register == RANGE_LOW:
            return self._result & 0xFF
        if register == AUTOTUNE_MIN_HIGH:
            return self._minimum_result >> 8
        if register == AUTOTUNE_MIN_LOW:
            return self._minimum_result & 0xFF
        return 0

    def _command(self, command: int) -> None:
        if command in (RANGE_INCHES, RANGE_CM, RANGE_MICROSECONDS):
            minimum_cm = self.minimum_range_cm
            distance = self._distance_cm
            if distance is None or distance > MAX_RANGE_CM:
                result = 0
            else:
                result = in_units(max(distance, minimum_cm), command)
            self._start(result, in_units(minimum_cm, command))
        elif FAKE_RANGE_FIRST <= command <= FAKE_RANGE_LAST:
            self._start(0, self._minimum_result)
        elif command == BURST:
            self._start(self._result, self._minimum_result)
        elif command == RESTART_AUTOTUNE:
            self._rangings = 0
        # 0xA0, 0xAA, 0xA5 (address change) and unknown commands: ignored

    def _start(self, result: int, minimum_result: int) -> None:
        self._pending = (result, minimum_result)
        self._busy_until_s = self._clock.now() + self._ranging_time_s

    def _update(self) -> None:
        if self._busy_until_s is None or self._clock.now() < self._busy_until_s:
            return
        assert self._pending is not None
        self._result, self._minimum_result = self._pending
        self._pending = None
        self._busy_until_s = None
        self._rangings += 1
