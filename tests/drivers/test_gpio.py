"""GPIO output lines: the kernel uAPI layout, errors, and the simulated line."""

from __future__ import annotations

import struct

import pytest

from engine.drivers.gpio import (
    GPIO_V2_GET_LINE_IOCTL,
    GPIO_V2_LINE_FLAG_ACTIVE_LOW,
    GPIO_V2_LINE_FLAG_OUTPUT,
    GPIO_V2_LINE_GET_VALUES_IOCTL,
    GPIO_V2_LINE_SET_VALUES_IOCTL,
    LINE_REQUEST_FD_OFFSET,
    LINE_REQUEST_SIZE,
    GpioOutputLine,
    OutputLine,
    pack_line_values,
    pack_output_request,
)
from engine.errors import DeviceError
from engine.sim.gpio import SimOutputLine


def test_struct_sizes_and_ioctl_numbers_match_linux_gpio_h():
    # Values printed by a C program compiled against linux/gpio.h (sizeof, offsetof and
    # the GPIO_V2_* macros) on x86-64; the layout has no pointer, so it is the same on arm64.
    assert LINE_REQUEST_SIZE == 592
    assert LINE_REQUEST_FD_OFFSET == 588
    assert len(pack_line_values(True)) == 16
    assert GPIO_V2_GET_LINE_IOCTL == 0xC250B407
    assert GPIO_V2_LINE_GET_VALUES_IOCTL == 0xC010B40E
    assert GPIO_V2_LINE_SET_VALUES_IOCTL == 0xC010B40F


def test_an_output_request_names_the_line_and_its_first_level():
    request = pack_output_request(17, consumer="vest-xshut", initial_high=True, active_low=True)
    assert len(request) == 592
    assert struct.unpack_from("=I", request, 0) == (17,)  # offsets[0]
    assert request[256:266] == b"vest-xshut"  # consumer
    flags, num_attrs = struct.unpack_from("=QI", request, 288)  # config.flags, num_attrs
    assert flags == GPIO_V2_LINE_FLAG_OUTPUT | GPIO_V2_LINE_FLAG_ACTIVE_LOW
    assert num_attrs == 1
    # attrs[0] at config + 32: id OUTPUT_VALUES (2), values bit 0 set, mask bit 0
    assert struct.unpack_from("=IIQQ", request, 288 + 32) == (2, 0, 1, 1)
    assert struct.unpack_from("=I", request, 560) == (1,)  # num_lines


def test_values_set_bit_zero_under_mask_zero():
    assert struct.unpack("=QQ", pack_line_values(True)) == (1, 1)
    assert struct.unpack("=QQ", pack_line_values(False)) == (0, 1)


def test_a_missing_gpio_chip_raises_device_error_naming_path_and_line(tmp_path):
    missing = tmp_path / "gpiochip9"
    with pytest.raises(DeviceError, match=rf"GPIO {missing} line 4: cannot open.*no such GPIO"):
        GpioOutputLine(missing, 4)


def test_a_file_that_is_not_a_gpio_chip_is_refused(tmp_path):
    not_a_chip = tmp_path / "plain"
    not_a_chip.write_bytes(b"")
    with pytest.raises(DeviceError, match=rf"GPIO {not_a_chip} line 0: cannot request"):
        GpioOutputLine(not_a_chip, 0)


def test_negative_offsets_are_refused():
    with pytest.raises(ValueError, match="-1"):
        pack_output_request(-1, consumer="vest", initial_high=False, active_low=False)


def test_a_simulated_line_drives_what_it_is_wired_to():
    levels: list[bool] = []
    line: OutputLine = SimOutputLine(levels.append)
    line.set(True)
    line.set(False)
    assert levels == [False, True, False]  # the initial level comes first, as on a real pin
