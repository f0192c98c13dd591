"""A register-level model of the NXP PCA9685 16-channel PWM controller.

What it models, from the NXP datasheet (section 7, "Functional description"):

* power-on registers: MODE1 0x11 (SLEEP, ALLCALL), MODE2 0x04, every LEDn "full off",
  PRE_SCALE 0x1E (200 Hz);
* the register pointer: auto-increments only when MODE1.AI is set (otherwise every byte of
  a block write lands on the same register); past LED15_OFF_H (0x45) it rolls over to
  MODE1, and from ALL_LED_ON_L (0xFA) up to PRE_SCALE (0xFE) and then to MODE1; the
  reserved addresses 0x46..0xF9 are not acknowledged;
* bits 7:5 of LEDn_ON_H / LEDn_OFF_H read 0; ALL_LED_* registers load every channel and
  read back 0;
* PRE_SCALE writes are ignored unless MODE1.SLEEP is set; values below 3 load as 3;
* SLEEP stops the oscillator and every output; leaving SLEEP the oscillator needs 500 us;
  going to sleep with a channel running sets RESTART, and the outputs stay stopped until
  1 is written to RESTART (at least 500 us after SLEEP cleared; an earlier write is
  ignored here) or a PWM register is written; EXTCLK, once set, stays set.

Physical outputs (what an LED sees): :meth:`SimPCA9685.duty` and :attr:`frequency_hz`.

Simplified: outputs update at once rather than at the end of the PWM cycle; MODE2 (INVRT,
OUTDRV, OCH, OUTNE) and the OE pin do not change the outputs; the sub-addresses, the LED
All Call address and the software-reset general call are not answered (a
:class:`SimI2CBus` gives each chip one address); an external clock is not modelled.
"""

from __future__ import annotations

import errno

from engine.clock import Clock
from engine.drivers.pca9685_registers import (
    ALL_LED_OFF_H,
    ALL_LED_ON_L,
    CHANNELS,
    COUNTS,
    FULL_BIT,
    LED0_ON_L,
    LED15_OFF_H,
    LED_STRIDE,
    MODE1,
    MODE1_AI,
    MODE1_EXTCLK,
    MODE1_POWER_ON,
    MODE1_RESTART,
    MODE1_SLEEP,
    MODE2,
    MODE2_POWER_ON,
    OSCILLATOR_WAKE_S,
    PRE_SCALE,
    PRE_SCALE_POWER_ON,
    PRESCALE_MIN,
    SUBADR1,
)
from engine.sim.i2c_bus import SimI2CDevice, bus_error

_TIME_TOLERANCE_S = 1e-9  # sums of float seconds: 0.1 + 0.0005 - 0.1 < 0.0005


class SimPCA9685(SimI2CDevice):
    """A PCA9685 driving 16 outputs; ``oscillator_hz`` is its internal 25 MHz clock."""

    def __init__(self, clock: Clock, address: int = 0x40, *, oscillator_hz: float = 25e6) -> None:
        super().__init__(address)
        self._clock = clock
        self.oscillator_hz = oscillator_hz
        self._registers = bytearray(256)
        self._registers[MODE1] = MODE1_POWER_ON
        self._registers[MODE2] = MODE2_POWER_ON
        self._registers[SUBADR1:LED0_ON_L] = bytes(
            [0xE2, 0xE4, 0xE8, 0xE0]
        )  # SUBADR1..3, ALLCALLADR
        for channel in range(CHANNELS):
            self._registers[self._led(channel) + 3] = FULL_BIT
        self._registers[PRE_SCALE] = PRE_SCALE_POWER_ON
        self._pointer = 0
        self._restart_pending = False
        self._awake_since_s: float | None = None  # None while SLEEP is set

    @staticmethod
    def _led(channel: int) -> int:
        return LED0_ON_L + LED_STRIDE * channel

    # -- what the outputs do -------------------------------------------------------------------
    @property
    def sleeping(self) -> bool:
        return bool(self._registers[MODE1] & MODE1_SLEEP)

    def _running(self) -> bool:
        if self._awake_since_s is None or self._restart_pending:
            return False
        return self._awake_for(self._clock.now())

    def _awake_for(self, now: float) -> bool:
        """Whether the oscillator has been running its 500 us wake-up time by ``now``."""
        if self._awake_since_s is None:
            return False
        return now - self._awake_since_s >= OSCILLATOR_WAKE_S - _TIME_TOLERANCE_S

    def duty(self, channel: int) -> float:
        """The duty cycle (0.0..1.0) channel ``channel`` outputs now; 0.0 while stopped."""
        if not 0 <= channel < CHANNELS:
            raise ValueError(f"PCA9685 channel must be 0..15, got {channel}")
        if not self._running():
            return 0.0
        return self._register_duty(channel)

    def _register_duty(self, channel: int) -> float:
        on_l, on_h, off_l, off_h = self._registers[self._led(channel) : self._led(channel) + 4]
        if off_h & FULL_BIT:
            return 0.0
        if on_h & FULL_BIT:
            return 1.0
        on, off = on_l | (on_h & 0x0F) << 8, off_l | (off_h & 0x0F) << 8
        return ((off - on) % COUNTS) / COUNTS

    @property
    def frequency_hz(self) -> float:
        """The PWM frequency in Hz the outputs run at (when running)."""
        return self.oscillator_hz / (COUNTS * (self._registers[PRE_SCALE] + 1))

    @property
    def prescale(self) -> int:
        return self._registers[PRE_SCALE]

    def peek(self, register: int) -> int:
        """A register as the chip holds it (for tests; ALL_LED_* hold nothing)."""
        return self._read_register(register)

    # -- the wire ------------------------------------------------------------------------------
    def _acknowledged(self, register: int) -> bool:
        return register <= LED15_OFF_H or register >= ALL_LED_ON_L

    def _advance(self) -> None:
        if not self._registers[MODE1] & MODE1_AI:
            return
        if self._pointer == LED15_OFF_H or self._pointer >= PRE_SCALE:
            self._pointer = MODE1
        else:
            self._pointer += 1

    def write(self, data: bytes) -> None:
        if not data:
            return
        if not self._acknowledged(data[0]):
            raise bus_error(errno.EREMOTEIO, self.address)  # reserved: not acknowledged
        self._pointer = data[0]
        pwm_written = False
        for value in data[1:]:
            pwm_written |= LED0_ON_L <= self._pointer <= ALL_LED_OFF_H and (
                self._pointer <= LED15_OFF_H or self._pointer >= ALL_LED_ON_L
            )
            self._write_register(self._pointer, value)
            self._advance()
        if pwm_written:
            self._restart_pending = False  # MODE2.OCH = 0: a PWM write clears RESTART at STOP

    def _write_register(self, register: int, value: int) -> None:
        if register == MODE1:
            self._write_mode1(value)
        elif register == MODE2:
            self._registers[MODE2] = value & 0x1F
        elif LED0_ON_L <= register <= LED15_OFF_H:
            self._registers[register] = value & 0x1F if (register - LED0_ON_L) % 2 else value
        elif ALL_LED_ON_L <= register <= ALL_LED_OFF_H:
            byte = register - ALL_LED_ON_L
            for channel in range(CHANNELS):
                self._registers[self._led(channel) + byte] = value & 0x1F if byte % 2 else value
        elif register == PRE_SCALE:
            if self.sleeping:  # blocked while the oscillator runs
                self._registers[PRE_SCALE] = max(value, PRESCALE_MIN)
        else:
            self._registers[register] = value  # sub-addresses, All Call, TestMode

    def _write_mode1(self, value: int) -> None:
        was_sleeping = self.sleeping
        now = self._clock.now()
        if value & MODE1_RESTART and not was_sleeping and self._awake_for(now):
            self._restart_pending = False
        extclk = (self._registers[MODE1] | value) & MODE1_EXTCLK  # sticky until power-off
        self._registers[MODE1] = (value & 0x3F) | extclk
        if self.sleeping and not was_sleeping:
            if any(self._register_duty(channel) > 0 for channel in range(CHANNELS)):
                self._restart_pending = True
            self._awake_since_s = None
        elif was_sleeping and not self.sleeping:
            self._awake_since_s = now

    def read(self, length: int) -> bytes:
        out = bytearray()
        for _ in range(length):
            out.append(self._read_register(self._pointer))
            self._advance()
        return bytes(out)

    def _read_register(self, register: int) -> int:
        if register == MODE1:
            restart = MODE1_RESTART if self._restart_pending else 0
            return self._registers[MODE1] | restart
        if ALL_LED_ON_L <= register <= ALL_LED_OFF_H:
            return 0
        return self._registers[register]
