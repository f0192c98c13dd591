"""The PCA9685 register map (NXP data sheet, section 7.3), shared by the driver and the
simulated chip.
"""

from __future__ import annotations

CHANNELS = 16
COUNTS = 4096  # PWM counts per period

MODE1 = 0x00
MODE1_RESTART = 0x80
MODE1_EXTCLK = 0x40
MODE1_AI = 0x20  # register pointer auto-increment
MODE1_SLEEP = 0x10  # oscillator off
MODE1_SUB1 = 0x08
MODE1_SUB2 = 0x04
MODE1_SUB3 = 0x02
MODE1_ALLCALL = 0x01
MODE1_POWER_ON = MODE1_SLEEP | MODE1_ALLCALL
MODE2 = 0x01
MODE2_INVRT = 0x10
MODE2_OCH = 0x08
MODE2_OUTDRV = 0x04  # totem-pole outputs (power-on default)
MODE2_POWER_ON = MODE2_OUTDRV
SUBADR1 = 0x02  # SUBADR1..3, then ALLCALLADR at 0x05
LED0_ON_L = 0x06  # LEDn_ON_L, LEDn_ON_H, LEDn_OFF_L, LEDn_OFF_H from here, 4 per channel
LED_STRIDE = 4
LED15_OFF_H = 0x45
ALL_LED_ON_L = 0xFA
ALL_LED_ON_H = 0xFB
ALL_LED_OFF_L = 0xFC
ALL_LED_OFF_H = 0xFD
PRE_SCALE = 0xFE
PRE_SCALE_POWER_ON = 0x1E  # 200 Hz at 25 MHz
TEST_MODE = 0xFF
FULL_BIT = 0x10  # bit 4 of LEDn_ON_H / LEDn_OFF_H: full on / full off
FULL = FULL_BIT << 8  # the same bit of the 16-bit ON / OFF value

PRESCALE_MIN = 3  # the chip holds at least 3 whatever is written
PRESCALE_MAX = 255
OSCILLATOR_WAKE_S = 500e-6
