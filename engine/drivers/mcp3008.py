"""Driver for the Microchip MCP3008 8-channel 10-bit ADC on SPI, read single-ended.

An alternative to the ADS1115 for the vest's force pads. It speaks to an
``spidev.SpiDev``-compatible object (``xfer2``, ``mode``, ``max_speed_hz``), opened by its
owner; the driver sets the SPI mode and clock the chip needs on it but never opens or
closes it.

Each reading is the data sheet's three-byte exchange for 8-bit SPI ports (section 6.1),
with chip select held low throughout::

    MOSI  0000 0001  S D2 D1 D0 xxxx  xxxx xxxx     start bit, then SGL/DIFF and channel
    MISO  ???? ????  ???? ? 0 B9 B8   B7 .. B0      null bit, then the 10-bit result

Code = 1024 * VIN / VREF, so volts = code * VREF / 1024.
"""

from __future__ import annotations

from engine.drivers.bus_protocols import SpiDevice
from engine.drivers.mcp3008_registers import (
    CHANNEL_SHIFT,
    CHANNELS,
    CODE_COUNT,
    MAX_CLOCK_AT_5V_HZ,
    NULL_BIT,
    RESULT_HIGH_MASK,
    SINGLE_ENDED,
    SPI_MODES,
    START_BIT,
    VDD_MAX_V,
    VREF_MIN_V,
)
from engine.errors import DeviceError

SPI_MODE = SPI_MODES[0]  # the chip also accepts mode 3
MIN_CLOCK_HZ = 10_000  # slower, the sample capacitor droops


def raw_to_volts(raw: int, vref_v: float) -> float:
    """Volts for a 10-bit code (0..1023) with reference ``vref_v`` volts."""
    if not 0 <= raw < CODE_COUNT:
        raise ValueError(f"MCP3008 code {raw} is outside 0..{CODE_COUNT - 1}")
    return raw * vref_v / CODE_COUNT


def command_bytes(channel: int) -> list[int]:
    """The three bytes that read CH``channel`` single-ended."""
    return [START_BIT, SINGLE_ENDED | channel << CHANNEL_SHIFT, 0x00]


class MCP3008:
    """An MCP3008 behind ``spi`` with reference voltage ``vref_v`` (0.25..5.5 V).

    ``max_speed_hz`` is the SPI clock set on ``spi``; the default 1 MHz is within the
    chip's limit at any supply (1.35 MHz at 2.7 V, 3.6 MHz at 5 V).
    """

    def __init__(
        self, spi: SpiDevice, *, vref_v: float = 3.3, max_speed_hz: int = 1_000_000
    ) -> None:
        if not VREF_MIN_V <= vref_v <= VDD_MAX_V:
            raise ValueError(f"MCP3008 VREF {vref_v} V is outside {VREF_MIN_V}..{VDD_MAX_V} V")
        if not MIN_CLOCK_HZ <= max_speed_hz <= MAX_CLOCK_AT_5V_HZ:
            raise ValueError(
                f"MCP3008 SPI clock {max_speed_hz} Hz is outside "
                f"{MIN_CLOCK_HZ}..{MAX_CLOCK_AT_5V_HZ} Hz"
            )
        self._spi = spi
        self.vref_v = vref_v
        spi.mode = SPI_MODE
        spi.max_speed_hz = max_speed_hz

    def read_raw(self, channel: int) -> int:
        """One conversion of CH``channel`` (0..7) against VSS, as a 10-bit code."""
        if not 0 <= channel < CHANNELS:
            raise ValueError(f"MCP3008 channel {channel} is outside 0..{CHANNELS - 1}")
        answer = self._spi.xfer2(command_bytes(channel))
        if len(answer) != 3:
            raise DeviceError(f"MCP3008 on SPI: expected 3 bytes back, got {len(answer)}")
        if answer[1] & NULL_BIT:
            raise DeviceError(
                f"MCP3008 on SPI: the null bit before the CH{channel} result is high "
                f"(answer {bytes(answer).hex(' ')}); is the chip connected and selected?"
            )
        return (answer[1] & RESULT_HIGH_MASK) << 8 | answer[2]

    def read_volts(self, channel: int) -> float:
        """CH``channel`` (0..7) against VSS, in volts."""
        return raw_to_volts(self.read_raw(channel), self.vref_v)
