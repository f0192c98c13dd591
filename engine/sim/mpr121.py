"""A register-level model of the NXP MPR121 12-pad capacitive touch controller.

What it models, after the MPR121 data sheet (Rev. 4, sections 5 and 6):

- Byte registers 0x00..0x80 behind a register pointer that auto-increments after every
  byte read or written, so a block read of 0x00..0x01 returns both touch status bytes.
- Power-on / soft reset (0x63 written to 0x80): every register back to its default,
  notably CONFIG1 (0x5C) = 0x10, CONFIG2 (0x5D) = 0x24 and ECR (0x5E) = 0x00 (stop mode).
- Stop and run mode: the chip runs while ECR enables electrodes (ELE_EN, bits 3:0, or
  ELEPROX_EN, bits 5:4). In run mode every write is ignored except ECR, the GPIO/LED
  registers 0x73..0x7A and the soft reset register, so a driver must stop the chip before
  it configures it.
- Electrode data: a finger adds capacitance, so the 10-bit filtered data (0x04..0x1D,
  little-endian pairs) of a touched pad drops by ``touch_delta_counts``. The baseline
  (0x1E..0x2A, the upper 8 of 10 bits) is initialised on entering run mode as the ECR
  calibration-lock bits (CL, bits 7:6) say, tracks the data while the pad is released and
  holds while it is touched.
- Touch detection with hysteresis: a pad becomes touched when baseline - data exceeds its
  touch threshold and released when it falls below its release threshold (0x41..0x58).
  The status registers 0x00/0x01 report only enabled electrodes, and only in run mode.
- IRQ: asserted (``irq_asserted``) when a touch status changes, cleared by reading the
  status registers.

What it simplifies: no sampling period, no debounce counts and no filter dynamics (each
bus access or touch is one instant scan), baseline tracking is immediate rather than
governed by MHD/NHD/NCL/FDL, the proximity electrode (ELEPROX) always reads zero,
auto-configuration and the GPIO/LED outputs only store their registers, and the pointer
wraps from 0xFF to 0x00 (the data sheet's finer wrap rules are not modelled).
"""

from __future__ import annotations

import threading

from engine.drivers.mpr121_registers import (
    BASELINE_0,
    CONFIG1,
    CONFIG1_DEFAULT,
    CONFIG2,
    CONFIG2_DEFAULT,
    DATA_MAX,
    ECR,
    ECR_CL_SHIFT,
    ECR_ELE_MASK,
    ECR_ELEPROX_MASK,
    FILTERED_DATA_0,
    GPIO_FIRST,
    GPIO_LAST,
    PADS,
    SOFT_RESET,
    SOFT_RESET_MAGIC,
    TOUCH_STATUS_H,
    TOUCH_STATUS_L,
    TOUCH_THRESHOLD_0,
)
from engine.sim.i2c_bus import SimI2CDevice


class SimMPR121(SimI2CDevice):
    """An MPR121 with 12 pads a simulated hand can touch.

    ``untouched_counts`` is each pad's 10-bit filtered data with nothing near it and
    ``touch_delta_counts`` how far a finger pulls it down (a firm touch on a vest pad,
    well above the usual touch threshold of 12).
    """

    def __init__(
        self,
        address: int = 0x5A,
        *,
        untouched_counts: int = 600,
        touch_delta_counts: int = 40,
    ) -> None:
        super().__init__(address)
        if not 0 < untouched_counts <= DATA_MAX:
            raise ValueError(f"untouched_counts {untouched_counts} is outside 1..{DATA_MAX}")
        if not 0 <= touch_delta_counts <= untouched_counts:
            raise ValueError(
                f"touch_delta_counts {touch_delta_counts} is outside 0..{untouched_counts}"
            )
        self._lock = threading.RLock()  # a world-model thread touches while the bus reads
        self._untouched_counts = untouched_counts
        self._touch_delta_counts = touch_delta_counts
        self._touching = [False] * PADS
        self._registers = bytearray(256)
        self._pointer = 0
        self._data = [0] * PADS
        self._baseline = [0] * PADS
        self._touched = [False] * PADS
        self.irq_asserted = False
        self.reset()

    # -- physical side ------------------------------------------------------------------
    def touch(self, pad: int, touching: bool = True) -> None:
        """Put a finger on ``pad`` (0..11), or take it away with ``touching=False``."""
        if not 0 <= pad < PADS:
            raise ValueError(f"MPR121 pad {pad} is outside 0..{PADS - 1}")
        with self._lock:
            self._touching[pad] = touching
            self._scan()

    @property
    def running(self) -> bool:
        """True in run mode (ECR enables at least one electrode)."""
        return self._enabled_pads() > 0 or bool(self._registers[ECR] & ECR_ELEPROX_MASK)

    def threshold(self, pad: int) -> tuple[int, int]:
        """The (touch, release) thresholds the chip holds for ``pad``, in counts."""
        register = TOUCH_THRESHOLD_0 + 2 * pad
        return self._registers[register], self._registers[register + 1]

    def reset(self) -> None:
        """Power-on reset: registers to defaults, stop mode, IRQ released."""
        with self._lock:
            self._registers = bytearray(256)
            self._registers[CONFIG1] = CONFIG1_DEFAULT
            self._registers[CONFIG2] = CONFIG2_DEFAULT
            self._data = [0] * PADS
            self._baseline = [0] * PADS
            self._touched = [False] * PADS
            self.irq_asserted = False

    # -- wire side ----------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if not data:
            return
        with self._lock:
            self._pointer = data[0]
            for value in data[1:]:
                self._write_register(self._pointer, value)
                self._pointer = (self._pointer + 1) & 0xFF

    def read(self, length: int) -> bytes:
        with self._lock:
            self._scan()
            out = bytearray()
            for _ in range(length):
                out.append(self._read_register(self._pointer))
                self._pointer = (self._pointer + 1) & 0xFF
            return bytes(out)

    # -- chip internals -----------------------------------------------------------------
    def _enabled_pads(self) -> int:
        return min(self._registers[ECR] & ECR_ELE_MASK, PADS)

    def _read_register(self, register: int) -> int:
        if register in (TOUCH_STATUS_L, TOUCH_STATUS_H):
            self.irq_asserted = False  # reading the status clears the interrupt
            status = sum(1 << pad for pad in range(PADS) if self._touched[pad])
            return (status >> 8) & 0xFF if register == TOUCH_STATUS_H else status & 0xFF
        if FILTERED_DATA_0 <= register < FILTERED_DATA_0 + 2 * PADS:
            value = self._data[(register - FILTERED_DATA_0) // 2]
            return (value >> 8) & 0x03 if (register - FILTERED_DATA_0) % 2 else value & 0xFF
        if BASELINE_0 <= register < BASELINE_0 + PADS:
            return self._baseline[register - BASELINE_0] >> 2
        if register <= BASELINE_0 + PADS:  # OOR status, ELEPROX data and baseline
            return 0
        if register > SOFT_RESET:
            return 0
        return self._registers[register]

    def _write_register(self, register: int, value: int) -> None:
        if register == SOFT_RESET:
            if value == SOFT_RESET_MAGIC:
                self.reset()
            return
        if register == ECR:
            self._set_ecr(value)
            return
        if GPIO_FIRST <= register <= GPIO_LAST:
            self._registers[register] = value  # GPIO/LED control is writable in run mode
            return
        if self.running:
            return  # the data sheet: other registers can only be written in stop mode
        if BASELINE_0 <= register < BASELINE_0 + PADS:
            self._baseline[register - BASELINE_0] = value << 2
            return
        if register < BASELINE_0 or register > SOFT_RESET:
            return  # status, filtered data and unimplemented registers are read-only
        self._registers[register] = value

    def _set_ecr(self, value: int) -> None:
        was_running = self.running
        self._registers[ECR] = value
        if self.running and not was_running:
            self._start_run()
        elif not self.running:
            # In stop mode the status reports no pad; the data registers keep their values.
            if any(self._touched):
                self.irq_asserted = True
            self._touched = [False] * PADS
        self._scan()

    def _start_run(self) -> None:
        """Measure every pad once and load the baselines as the CL bits ask."""
        calibration_lock = (self._registers[ECR] >> ECR_CL_SHIFT) & 0x03
        for pad in range(self._enabled_pads()):
            self._data[pad] = self._measure(pad)
            if calibration_lock == 0b10:
                self._baseline[pad] = self._data[pad] & 0x3E0  # the 5 high bits
            elif calibration_lock == 0b11:
                self._baseline[pad] = self._data[pad] & 0x3FC
            self._touched[pad] = False

    def _measure(self, pad: int) -> int:
        delta = self._touch_delta_counts if self._touching[pad] else 0
        return max(0, self._untouched_counts - delta)

    def _scan(self) -> None:
        """One measurement of the enabled pads, as the chip does every sample period."""
        if not self.running:
            return
        tracking = (self._registers[ECR] >> ECR_CL_SHIFT) & 0x03 != 0b01
        for pad in range(PADS):
            if pad >= self._enabled_pads():
                if self._touched[pad]:
                    self._touched[pad] = False
                    self.irq_asserted = True
                continue
            self._data[pad] = self._measure(pad)
            touch_threshold, release_threshold = self.threshold(pad)
            delta = self._baseline[pad] - self._data[pad]
            if not self._touched[pad] and delta > touch_threshold:
                self._touched[pad] = True
                self.irq_asserted = True
            elif self._touched[pad] and delta < release_threshold:
                self._touched[pad] = False
                self.irq_asserted = True
            if tracking and not self._touched[pad]:
                self._baseline[pad] = self._data[pad] & 0x3FC
