"""ST's default tuning of the VL53L0X, as data: the register writes its API makes in
``VL53L0X_StaticInit`` (``DefaultTuningSettings``, "update 02/11/2015_v36" of ST's
``vl53l0x_tuning.h``), which Pololu's and Adafruit's drivers make as well.

Each entry is one byte written to one register, in order; ``0xFF`` selects the register
page (0x00 the documented map, 0x01 the private page), so the order is part of the data.
ST documents the few registers it names (comments below); the rest are ST's settings for
its own firmware, written as given. After the table the chip ranges with a ~33 ms timing
budget: a 14 PCLK pre-range and a 10 PCLK final-range VCSEL period, the sequence steps
TCC, DSS, pre-range and final range, and a final-range signal rate limit of 0.25 MCPS.
"""

from __future__ import annotations

from engine.drivers.vl53l0x_registers import (
    FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT,
    PAGE_SELECT,
)

TUNING_SIGNAL_RATE_LIMIT = 0x0020  # what the table leaves there: 0.25 MCPS

DEFAULT_TUNING: tuple[tuple[int, int], ...] = (
    (PAGE_SELECT, 0x01),
    (0x00, 0x00),
    (PAGE_SELECT, 0x00),
    (0x09, 0x00),  # SYSTEM_RANGE_CONFIG
    (0x10, 0x00),
    (0x11, 0x00),
    (0x24, 0x01),
    (0x25, 0xFF),
    (0x75, 0x00),
    (PAGE_SELECT, 0x01),
    (0x4E, 0x2C),  # DYNAMIC_SPAD_NUM_REQUESTED_REF_SPAD
    (0x48, 0x00),
    (0x30, 0x20),  # ALGO_PHASECAL_LIM
    (PAGE_SELECT, 0x00),
    (0x30, 0x09),  # ALGO_PHASECAL_CONFIG_TIMEOUT
    (0x54, 0x00),
    (0x31, 0x04),
    (0x32, 0x03),  # GLOBAL_CONFIG_VCSEL_WIDTH
    (0x40, 0x83),
    (0x46, 0x25),  # MSRC_CONFIG_TIMEOUT_MACROP: 38 macro periods
    (0x60, 0x00),  # MSRC_CONFIG_CONTROL
    (0x27, 0x00),  # PRE_RANGE_CONFIG_MIN_SNR
    (0x50, 0x06),  # PRE_RANGE_CONFIG_VCSEL_PERIOD: 14 PCLK
    (0x51, 0x00),  # PRE_RANGE_CONFIG_TIMEOUT_MACROP_HI
    (0x52, 0x96),  # ... _LO: 151 macro periods
    (0x56, 0x08),  # PRE_RANGE_CONFIG_VALID_PHASE_LOW
    (0x57, 0x30),  # PRE_RANGE_CONFIG_VALID_PHASE_HIGH
    (0x61, 0x00),  # PRE_RANGE_CONFIG_SIGMA_THRESH_HI
    (0x62, 0x00),  # PRE_RANGE_CONFIG_SIGMA_THRESH_LO
    (0x64, 0x00),  # PRE_RANGE_MIN_COUNT_RATE_RTN_LIMIT, high byte
    (0x65, 0x00),  # ... low byte
    (0x66, 0xA0),
    (PAGE_SELECT, 0x01),
    (0x22, 0x32),
    (0x47, 0x14),
    (0x49, 0xFF),
    (0x4A, 0x00),
    (PAGE_SELECT, 0x00),
    (0x7A, 0x0A),
    (0x7B, 0x00),
    (0x78, 0x21),
    (PAGE_SELECT, 0x01),
    (0x23, 0x34),
    (0x42, 0x00),
    (0x44, 0xFF),
    (0x45, 0x26),
    (0x46, 0x05),
    (0x40, 0x40),
    (0x0E, 0x06),
    (0x20, 0x1A),
    (0x43, 0x40),
    (PAGE_SELECT, 0x00),
    (0x34, 0x03),
    (0x35, 0x44),
    (PAGE_SELECT, 0x01),
    (0x31, 0x04),
    (0x4B, 0x09),
    (0x4C, 0x05),
    (0x4D, 0x04),
    (PAGE_SELECT, 0x00),
    (FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT, TUNING_SIGNAL_RATE_LIMIT >> 8),
    (FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT + 1, TUNING_SIGNAL_RATE_LIMIT & 0xFF),
    (0x47, 0x08),  # FINAL_RANGE_CONFIG_VALID_PHASE_LOW
    (0x48, 0x28),  # FINAL_RANGE_CONFIG_VALID_PHASE_HIGH
    (0x67, 0x00),  # FINAL_RANGE_CONFIG_MIN_SNR
    (0x70, 0x04),  # FINAL_RANGE_CONFIG_VCSEL_PERIOD: 10 PCLK
    (0x71, 0x01),  # FINAL_RANGE_CONFIG_TIMEOUT_MACROP_HI
    (0x72, 0xFE),  # ... _LO: 509 macro periods
    (0x76, 0x00),
    (0x77, 0x00),
    (PAGE_SELECT, 0x01),
    (0x0D, 0x01),
    (PAGE_SELECT, 0x00),
    (0x80, 0x01),  # POWER_MANAGEMENT_GO1_POWER_FORCE
    (0x01, 0xF8),  # SYSTEM_SEQUENCE_CONFIG: TCC, DSS, pre-range, final range
    (PAGE_SELECT, 0x01),
    (0x8E, 0x01),
    (0x00, 0x01),
    (PAGE_SELECT, 0x00),
    (0x80, 0x00),
)
"""ST's default tuning: (register, value) byte writes, in the order ST makes them."""
