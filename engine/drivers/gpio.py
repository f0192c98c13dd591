"""Digital output lines: the protocol drivers use, and Linux's GPIO character device.

Drivers that toggle a pin (the VL53L0X XSHUT chain) take an :class:`OutputLine`, so the
same code drives a real pin, a simulated one (:mod:`engine.sim.gpio`) or anyone
else's object with a ``set(high)`` method.

:class:`GpioOutputLine` talks to ``/dev/gpiochipN`` through the kernel's v2 uAPI ioctls
(``linux/gpio.h``, Linux 5.10 and later) with nothing but :mod:`fcntl`, so it needs no
third-party package. The struct layouts below are packed by hand; their sizes and the ioctl
numbers are checked against the kernel header in the tests.
"""

from __future__ import annotations

import errno
import fcntl
import os
import struct
from pathlib import Path
from typing import Protocol

from engine.drivers.device_errors import errno_in_words
from engine.errors import DeviceError


class OutputLine(Protocol):
    """A digital output: ``set(True)`` drives it high, ``set(False)`` low."""

    def set(self, high: bool) -> None: ...


# -- linux/gpio.h, v2 uAPI ------------------------------------------------------------------
GPIO_MAX_NAME_SIZE = 32
GPIO_V2_LINES_MAX = 64
GPIO_V2_LINE_NUM_ATTRS_MAX = 10

GPIO_V2_LINE_FLAG_ACTIVE_LOW = 1 << 1
GPIO_V2_LINE_FLAG_INPUT = 1 << 2
GPIO_V2_LINE_FLAG_OUTPUT = 1 << 3

GPIO_V2_LINE_ATTR_ID_FLAGS = 1
GPIO_V2_LINE_ATTR_ID_OUTPUT_VALUES = 2

# struct gpio_v2_line_config_attribute: {u32 id, u32 padding, u64 flags|values, u64 mask}
_CONFIG_ATTRIBUTE = "IIQQ"
# struct gpio_v2_line_request: offsets[64], consumer[32], config {u64 flags, u32 num_attrs,
# u32 padding[5], attrs[10]}, u32 num_lines, u32 event_buffer_size, u32 padding[5], s32 fd.
# Every field already sits on its natural alignment, so "=" (no padding) matches the C layout.
LINE_REQUEST_FORMAT = (
    f"={GPIO_V2_LINES_MAX}I{GPIO_MAX_NAME_SIZE}sQI5I"
    + _CONFIG_ATTRIBUTE * GPIO_V2_LINE_NUM_ATTRS_MAX
    + "II5Ii"
)
LINE_REQUEST_SIZE = struct.calcsize(LINE_REQUEST_FORMAT)  # 592 bytes
LINE_REQUEST_FD_OFFSET = LINE_REQUEST_SIZE - 4
# struct gpio_v2_line_values: {u64 bits, u64 mask}
LINE_VALUES_FORMAT = "=QQ"
LINE_VALUES_SIZE = struct.calcsize(LINE_VALUES_FORMAT)  # 16 bytes

_IOC_WRITE = 1
_IOC_READ = 2
_GPIO_IOCTL_TYPE = 0xB4


def ioctl_readwrite(kind: int, number: int, size: int) -> int:
    """The ``_IOWR(kind, number, size)`` request code of asm-generic/ioctl.h."""
    return ((_IOC_READ | _IOC_WRITE) << 30) | (size << 16) | (kind << 8) | number


GPIO_V2_GET_LINE_IOCTL = ioctl_readwrite(_GPIO_IOCTL_TYPE, 0x07, LINE_REQUEST_SIZE)
GPIO_V2_LINE_GET_VALUES_IOCTL = ioctl_readwrite(_GPIO_IOCTL_TYPE, 0x0E, LINE_VALUES_SIZE)
GPIO_V2_LINE_SET_VALUES_IOCTL = ioctl_readwrite(_GPIO_IOCTL_TYPE, 0x0F, LINE_VALUES_SIZE)


def pack_output_request(
    offset: int, *, consumer: str, initial_high: bool, active_low: bool
) -> bytearray:
    """A ``gpio_v2_line_request`` asking for one output line driven to ``initial_high``."""
    if not 0 <= offset < 2**32:
        raise ValueError(f"GPIO line offset must be a non-negative 32-bit number, got {offset}")
    offsets = [offset] + [0] * (GPIO_V2_LINES_MAX - 1)
    flags = GPIO_V2_LINE_FLAG_OUTPUT | (GPIO_V2_LINE_FLAG_ACTIVE_LOW if active_low else 0)
    # One attribute: the output value of line 0 of this request, applied atomically with
    # the direction, so the pin never glitches to the wrong level.
    attributes = [GPIO_V2_LINE_ATTR_ID_OUTPUT_VALUES, 0, int(initial_high), 1]
    attributes += [0, 0, 0, 0] * (GPIO_V2_LINE_NUM_ATTRS_MAX - 1)
    name = consumer.encode("utf-8")[: GPIO_MAX_NAME_SIZE - 1]
    return bytearray(
        struct.pack(
            LINE_REQUEST_FORMAT,
            *offsets,
            name,
            flags,
            1,  # num_attrs
            *([0] * 5),
            *attributes,
            1,  # num_lines
            0,  # event_buffer_size
            *([0] * 5),
            -1,  # fd: filled in by the kernel
        )
    )


def pack_line_values(high: bool) -> bytearray:
    """A ``gpio_v2_line_values`` setting line 0 of a request."""
    return bytearray(struct.pack(LINE_VALUES_FORMAT, int(high), 1))


_GPIO_ADVICE = {
    errno.ENOENT: "no such GPIO chip",
    errno.EACCES: "no permission (is the user in the gpio group?)",
    errno.EPERM: "no permission (is the user in the gpio group?)",
    errno.EBUSY: "the line is already used by another program",
    errno.EINVAL: "the chip has no such line, or rejected the request",
    errno.ENOTTY: "not a GPIO character device (kernel older than 5.10?)",
}


def _chip_path(chip: str | Path | int) -> Path:
    if isinstance(chip, int):
        return Path(f"/dev/gpiochip{chip}")
    path = Path(chip)
    return path if path.is_absolute() or "/" in str(chip) else Path("/dev") / path


class GpioOutputLine:
    """One output line of a Linux GPIO chip (``/dev/gpiochipN``), via the v2 uAPI.

    ``chip`` is a path, a name such as ``"gpiochip0"`` or a number; ``offset`` is the
    line's number on that chip (on a Raspberry Pi, the BCM GPIO number on gpiochip0 or
    gpiochip4 depending on the model). The line is requested as an output driven to
    ``initial_high`` at once, and released by :meth:`close`. Errors raise
    :class:`DeviceError` naming the chip, the line and the errno in words.
    """

    def __init__(
        self,
        chip: str | Path | int,
        offset: int,
        *,
        consumer: str = "vest",
        initial_high: bool = False,
        active_low: bool = False,
    ) -> None:
        self.path = _chip_path(chip)
        self.offset = offset
        request = pack_output_request(
            offset, consumer=consumer, initial_high=initial_high, active_low=active_low
        )
        try:
            chip_fd = os.open(self.path, os.O_RDWR | os.O_CLOEXEC)
        except OSError as err:
            raise self._error("cannot open", err) from err
        try:
            fcntl.ioctl(chip_fd, GPIO_V2_GET_LINE_IOCTL, request, True)
        except OSError as err:
            raise self._error("cannot request", err) from err
        finally:
            os.close(chip_fd)  # the line request lives on in its own file descriptor
        (self._fd,) = struct.unpack_from("=i", request, LINE_REQUEST_FD_OFFSET)
        self._high = initial_high

    def _error(self, action: str, err: OSError) -> DeviceError:
        words = errno_in_words(err.errno, _GPIO_ADVICE)
        return DeviceError(
            err.errno, f"GPIO {self.path} line {self.offset}: {action} the line: {words}"
        )

    @property
    def high(self) -> bool:
        """The level last driven (logical: ``active_low`` inverts the pin)."""
        return self._high

    def set(self, high: bool) -> None:
        """Drive the line high (``True``) or low (``False``)."""
        if self._fd < 0:
            raise DeviceError(f"GPIO {self.path} line {self.offset} is closed")
        try:
            fcntl.ioctl(self._fd, GPIO_V2_LINE_SET_VALUES_IOCTL, pack_line_values(high), True)
        except OSError as err:
            raise self._error("cannot set", err) from err
        self._high = high

    def close(self) -> None:
        """Release the line (it keeps its last level or floats, as the chip decides)."""
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def __enter__(self) -> GpioOutputLine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
