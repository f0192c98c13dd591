"""The VL53L0X register map, as ST's API names the registers (the data sheet names few).

Page 0 is the documented map; ``PAGE_SELECT`` (0xFF) selects the others: the private
page 1 (the stop variable, the dynamic SPAD settings) and pages 6 and 7, through which ST's
API reads the factory NVM. 16-bit registers are big-endian.
"""

from __future__ import annotations

POWER_ON_ADDRESS = 0x29  # and again after every boot (XSHUT high)

SYSRANGE_START = 0x00
SYSRANGE_START_SINGLESHOT = 0x01  # bit 0: start; clears itself once ranging has begun
SYSRANGE_START_BACK_TO_BACK = 0x02  # bit 1: range continuously, one after another
SYSTEM_SEQUENCE_CONFIG = 0x01
SYSTEM_INTERRUPT_CONFIG_GPIO = 0x0A
INTERRUPT_NEW_SAMPLE_READY = 0x04
SYSTEM_INTERRUPT_CLEAR = 0x0B
RESULT_INTERRUPT_STATUS = 0x13
RESULT_INTERRUPT_MASK = 0x07
RESULT_RANGE_STATUS = 0x14
RESULT_RANGE_MM_OFFSET = 10  # range in mm, big-endian 16-bit, at RESULT_RANGE_STATUS + 10
RESULT_RANGE_MM = RESULT_RANGE_STATUS + RESULT_RANGE_MM_OFFSET  # 0x1E..0x1F
# Bits 6:3 of RESULT_RANGE_STATUS: the device's range status; 11 means a valid range.
DEVICE_RANGE_STATUS_SHIFT = 3
DEVICE_RANGE_STATUS_VALID = 11
DEVICE_RANGE_STATUS_MSRC_NO_TARGET = 4
RANGE_OUT_OF_RANGE_MM = 8190  # the chip reports 8190 or 8191 when nothing is in range
RESULT_BLOCK_LENGTH = 12
FINAL_RANGE_CONFIG_MIN_COUNT_RATE_RTN_LIMIT = 0x44  # 16-bit, Q9.7 MCPS
MSRC_CONFIG_CONTROL = 0x60
MSRC_DISABLE_SIGNAL_RATE_CHECKS = 0x12  # bit 1 MSRC, bit 4 pre-range
MSRC_CONFIG_TIMEOUT_MACROP = 0x46
PRE_RANGE_CONFIG_VCSEL_PERIOD = 0x50
PRE_RANGE_CONFIG_TIMEOUT_MACROP_HI = 0x51  # 16-bit
FINAL_RANGE_CONFIG_VCSEL_PERIOD = 0x70
FINAL_RANGE_CONFIG_TIMEOUT_MACROP_HI = 0x71  # 16-bit
GLOBAL_CONFIG_SPAD_ENABLES_REF_0 = 0xB0  # six bytes, 0xB0..0xB5
GLOBAL_CONFIG_REF_EN_START_SELECT = 0xB6
REF_EN_START_SELECT = 0xB4  # the reference array's first SPAD
GPIO_HV_MUX_ACTIVE_HIGH = 0x84
GPIO_HV_MUX_POLARITY_HIGH = 0x10
I2C_STANDARD_MODE = 0x88
VHV_CONFIG_PAD_SCL_SDA_EXTSUP_HV = 0x89
VHV_CONFIG_2V8 = 0x01
I2C_SLAVE_DEVICE_ADDRESS = 0x8A
IDENTIFICATION_MODEL_ID = 0xC0
IDENTITY = (0xEE, 0xAA, 0x10)  # registers 0xC0, 0xC1, 0xC2 (model, ?, revision)

# Register pages (0xFF): the private page 1 holds the stop variable (0x91) and the
# dynamic SPAD settings; pages 6 and 7 give access to the factory NVM.
POWER_MANAGEMENT = 0x80
PAGE_SELECT = 0xFF
PRIVATE_PAGE = 0x01
STOP_VARIABLE = 0x91
DYNAMIC_SPAD_NUM_REQUESTED_REF_SPAD = 0x4E  # private page
DYNAMIC_SPAD_REF_EN_START_OFFSET = 0x4F  # private page
DYNAMIC_SPADS_REQUESTED = 0x2C
NVM_ENABLE_PAGE = 0x06
NVM_PAGE = 0x07
NVM_CONTROL = 0x83  # page 6: bit 2 enables NVM access; page 7: the read strobe
NVM_ENABLE = 0x04
NVM_POWER = 0x81  # page 7
NVM_DATA = 0x90  # page 7: the word read, big-endian, 0x90..0x93
NVM_ADDRESS = 0x94  # page 7: the word to read
NVM_READ_DONE = 0x01  # NVM_CONTROL on page 7 once the strobe has read the word
# NVM words: the reference SPAD count (bits 14:8) and kind (bit 15, 1 = aperture), and
# the 6-byte map of working reference SPADs (bytes 0..3, then 4..5 in the high half).
NVM_SPAD_INFO = 0x6B
NVM_GOOD_SPAD_MAP = (0x24, 0x25)
ENTER_PRIVATE_PAGE = ((POWER_MANAGEMENT, 0x01), (PAGE_SELECT, 0x01), (0x00, 0x00))
LEAVE_PRIVATE_PAGE = ((0x00, 0x01), (PAGE_SELECT, 0x00), (POWER_MANAGEMENT, 0x00))

SEQUENCE_ALL = 0xFF
SEQUENCE_DSS_PRE_FINAL = 0xE8  # DSS, pre-range and final range; no TCC, no MSRC
SEQUENCE_VHV_CALIBRATION = 0x01
SEQUENCE_PHASE_CALIBRATION = 0x02
VHV_CALIBRATION_START = 0x40

TBOOT_MAX_S = 0.0012  # boot time after XSHUT rises, data sheet maximum
