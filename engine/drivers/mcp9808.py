"""Driver for the Microchip MCP9808 digital temperature sensor (I2C, default 0x18).

The vest reads it on request ("what is the temperature?"). The chip converts continuously
on its own, so a reading is one register read: the ambient temperature register (0x05)
holds the latest conversion, 13-bit two's complement in 1/16 degC with three alert flags
above it, most significant byte first on the wire.

Construction checks identity (manufacturer ID 0x0054, device ID 0x04), wakes the chip if
it was left in shutdown and sets the resolution; a finer resolution converts more slowly
(0.5 / 0.25 / 0.125 / 0.0625 degC every 30 / 65 / 130 / 250 ms).
"""

from __future__ import annotations

from dataclasses import dataclass

from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, i2c_place, not_found
from engine.drivers.mcp9808_registers import (
    CONFIG,
    CONFIG_SHDN,
    DEVICE_ID,
    DEVICE_ID_VALUE,
    FLAG_CRIT,
    FLAG_LOWER,
    FLAG_UPPER,
    LIMIT_MASK,
    MANUFACTURER_ID,
    MANUFACTURER_ID_VALUE,
    OPERATING_MAX_C,
    OPERATING_MIN_C,
    RESOLUTION,
    RESOLUTIONS,
    SIGN,
    T_AMBIENT,
    T_CRIT,
    T_LOWER,
    T_UPPER,
    TEMPERATURE_MASK,
)
from engine.errors import DeviceError

# Resolution in degC -> (register code, conversion time in seconds).
RESOLUTIONS_C: dict[float, tuple[int, float]] = {
    step_c: (code, time_s) for code, (step_c, time_s) in RESOLUTIONS.items()
}
LIMIT_MIN_C = -256.0
LIMIT_MAX_C = 255.75


def raw_to_celsius(word: int) -> float:
    """Degrees Celsius from the ambient register's 16-bit word (flag bits ignored)."""
    if not 0 <= word <= 0xFFFF:
        raise ValueError(f"MCP9808 register word {word} is outside 0..0xFFFF")
    sixteenths = word & TEMPERATURE_MASK
    if word & SIGN:
        sixteenths -= 0x1000
    return sixteenths / 16


def celsius_to_fahrenheit(celsius: float) -> float:
    """Degrees Fahrenheit from degrees Celsius."""
    return celsius * 9 / 5 + 32


def celsius_to_limit_word(celsius: float) -> int:
    """A limit register word (0.25 degC steps in bits 12:2) for ``celsius``, rounded."""
    if not LIMIT_MIN_C <= celsius <= LIMIT_MAX_C:
        raise ValueError(
            f"MCP9808 limit {celsius} degC is outside {LIMIT_MIN_C}..{LIMIT_MAX_C} degC"
        )
    quarters = round(celsius * 4)
    return (quarters << 2) & LIMIT_MASK


@dataclass(frozen=True)
class AlertFlags:
    """The ambient register's flags from the latest conversion."""

    critical: bool  # TA >= TCRIT
    upper: bool  # TA > TUPPER
    lower: bool  # TA < TLOWER


def word_to_flags(word: int) -> AlertFlags:
    """The three alert flags of an ambient register word."""
    return AlertFlags(
        critical=bool(word & FLAG_CRIT),
        upper=bool(word & FLAG_UPPER),
        lower=bool(word & FLAG_LOWER),
    )


def _resolution_entry(resolution_c: float) -> tuple[int, float]:
    entry = RESOLUTIONS_C.get(resolution_c)
    if entry is None:
        raise ValueError(
            f"MCP9808 resolution {resolution_c!r} degC is not one of 0.5, 0.25, 0.125, 0.0625"
        )
    return entry


class MCP9808:
    """An MCP9808 on an ``smbus2.SMBus``-compatible ``bus``."""

    def __init__(self, bus: I2CBus, *, address: int = 0x18, resolution_c: float = 0.0625) -> None:
        _resolution_entry(resolution_c)
        self._bus = bus
        self.address = address
        self._check_identity()
        config = self._read_word(CONFIG)
        if config & CONFIG_SHDN:
            self._write_word(CONFIG, config & ~CONFIG_SHDN)  # allowed even when locked
        self._resolution_c = resolution_c
        self.set_resolution(resolution_c)

    # -- settings -----------------------------------------------------------------------
    @property
    def resolution_c(self) -> float:
        """The temperature step in degC (0.5, 0.25, 0.125 or 0.0625)."""
        return self._resolution_c

    @property
    def conversion_time_s(self) -> float:
        """How often the chip refreshes its reading at the current resolution, seconds."""
        return RESOLUTIONS_C[self._resolution_c][1]

    def set_resolution(self, resolution_c: float) -> None:
        """Choose the temperature step: 0.5, 0.25, 0.125 or 0.0625 degC."""
        code, _ = _resolution_entry(resolution_c)
        self._bus.write_byte_data(self.address, RESOLUTION, code)
        self._resolution_c = resolution_c

    def set_alert_limits(self, *, lower_c: float, upper_c: float, critical_c: float) -> None:
        """Set the window (TLOWER, TUPPER) and the critical limit, in degC (0.25 steps).

        The chip ignores these writes once its window or critical lock is set.
        """
        if not lower_c <= upper_c <= critical_c:
            raise ValueError(
                f"MCP9808 limits must satisfy lower <= upper <= critical, got "
                f"{lower_c}, {upper_c}, {critical_c} degC"
            )
        for register, celsius in ((T_LOWER, lower_c), (T_UPPER, upper_c), (T_CRIT, critical_c)):
            self._write_word(register, celsius_to_limit_word(celsius))

    # -- readings -----------------------------------------------------------------------
    def read_temperature_c(self) -> float:
        """The latest conversion, degrees Celsius (negative below freezing).

        Raises :class:`~engine.drivers.device_errors.ImplausibleReadingError` for a value
        outside the chip's operating range (-40..125 degC): a garbled transfer, not air.
        """
        celsius = raw_to_celsius(self._read_word(T_AMBIENT))
        if not OPERATING_MIN_C <= celsius <= OPERATING_MAX_C:
            raise ImplausibleReadingError(
                chip="MCP9808",
                place=i2c_place(self.address),
                what="temperature",
                value=f"{celsius:g} degC",
                plausible=f"{OPERATING_MIN_C:g}..{OPERATING_MAX_C:g} degC",
            )
        return celsius

    def read_temperature_f(self) -> float:
        """The latest conversion, degrees Fahrenheit."""
        return celsius_to_fahrenheit(self.read_temperature_c())

    def read_alert_flags(self) -> AlertFlags:
        """Which limits the latest conversion crossed."""
        return word_to_flags(self._read_word(T_AMBIENT))

    # -- helpers ------------------------------------------------------------------------
    def _check_identity(self) -> None:
        try:
            manufacturer = self._read_word(MANUFACTURER_ID)
            device = self._read_word(DEVICE_ID)
        except DeviceError:
            raise
        except OSError as error:
            raise not_found("MCP9808", self.address, error) from error
        if manufacturer != MANUFACTURER_ID_VALUE or device >> 8 != DEVICE_ID_VALUE:
            raise DeviceError(
                f"MCP9808 at I2C 0x{self.address:02X} failed its identity check: "
                f"manufacturer ID 0x{manufacturer:04X} (expected 0x{MANUFACTURER_ID_VALUE:04X}),"
                f" device ID 0x{device >> 8:02X} (expected 0x{DEVICE_ID_VALUE:02X})"
            )

    def _read_word(self, register: int) -> int:
        msb, lsb = self._bus.read_i2c_block_data(self.address, register, 2)
        return msb << 8 | lsb

    def _write_word(self, register: int, value: int) -> None:
        self._bus.write_i2c_block_data(self.address, register, [value >> 8, value & 0xFF])
