"""Driver for the TI ADS1115 16-bit ADC (I2C, default 0x48), read single-ended.

The vest's two Interlink FSR 406 force pads sit in voltage dividers on AIN0 and AIN1; a
:class:`~engine.drivers.force_calibration.ForceCalibration` from the robot config turns
the volts into newtons.

Each reading is one single-shot conversion, as the data sheet describes: write the config
register with OS=1 (start), MUX (AINx against GND), PGA (full scale), MODE=1 (single
shot, power down after) and DR (data rate); wait 1/DR plus the oscillator's 10 % tolerance
on the injected clock; poll the OS bit (0 while converting) a bounded number of times; read
the conversion register, 16-bit big-endian two's complement.

Registers are 16-bit, most significant byte first on the wire, behind a pointer byte, so
the driver uses plain I2C block transfers rather than SMBus words (which are LSB first).

The chip has no identity register; construction writes the config register (without
starting a conversion) and reads it back, which an ADS1115 echoes.
"""

from __future__ import annotations

import math

from engine.clock import Clock
from engine.drivers.ads1115_registers import (
    CODE_MAX,
    CODE_MIN,
    COMP_QUE_DISABLE,
    CONFIG,
    CONVERSION,
    DATA_RATES_SPS,
    DR_SHIFT,
    INPUT_MARGIN_V,
    MODE_SINGLE_SHOT,
    MUX_SHIFT,
    MUX_SINGLE_ENDED,
    OS,
    PGA_FULL_SCALE_V,
    PGA_GAINS,
    PGA_SHIFT,
)
from engine.drivers.bus_protocols import I2CBus
from engine.drivers.device_errors import ImplausibleReadingError, i2c_place, not_found
from engine.errors import DeviceError

# PGA gain -> full-scale range in volts (+/-), in PGA code order.
GAIN_FULL_SCALE_V: dict[float, float] = dict(
    zip(PGA_GAINS, PGA_FULL_SCALE_V[: len(PGA_GAINS)], strict=True)
)

OSCILLATOR_TOLERANCE = 0.10  # the internal oscillator is within 10 %
MAX_POLLS = 10
INPUT_MIN_V = -INPUT_MARGIN_V  # below GND: a single-ended input never reads lower


def raw_to_volts(raw: int, full_scale_v: float) -> float:
    """Volts for a conversion code: ``raw`` (-32768..32767) times full scale / 32768."""
    if not CODE_MIN <= raw <= CODE_MAX:
        raise ValueError(f"ADS1115 code {raw} is outside {CODE_MIN}..{CODE_MAX}")
    if not full_scale_v > 0:
        raise ValueError(f"full scale {full_scale_v} V must be positive")
    return raw * full_scale_v / 32768


def word_to_code(msb: int, lsb: int) -> int:
    """The two's complement code of the conversion register's two bytes (MSB first)."""
    word = msb << 8 | lsb
    return word - 0x10000 if word & 0x8000 else word


def lowest_single_ended_code(full_scale_v: float) -> int:
    """The most negative code a single-ended input can give at ``full_scale_v`` volts:
    that of -0.3 V (the inputs' absolute maximum below GND), or -32768 if that is beyond."""
    return max(CODE_MIN, math.floor(INPUT_MIN_V * 32768 / full_scale_v))


def pga_code(gain: float) -> int:
    """The PGA field for a gain of 2/3, 1, 2, 4, 8 or 16; ``ValueError`` otherwise."""
    for code, known in enumerate(GAIN_FULL_SCALE_V):
        if math.isclose(gain, known, rel_tol=1e-6):
            return code
    raise ValueError(
        f"ADS1115 gain {gain!r} is not one of 2/3, 1, 2, 4, 8, 16 "
        "(full scale 6.144, 4.096, 2.048, 1.024, 0.512, 0.256 V)"
    )


def data_rate_code(data_rate_sps: int) -> int:
    """The DR field for one of the eight data rates; ``ValueError`` otherwise."""
    if data_rate_sps not in DATA_RATES_SPS:
        raise ValueError(
            f"ADS1115 data rate {data_rate_sps!r} SPS is not one of "
            f"{', '.join(map(str, DATA_RATES_SPS))}"
        )
    return DATA_RATES_SPS.index(data_rate_sps)


class ADS1115:
    """An ADS1115 on an ``smbus2.SMBus``-compatible ``bus``, waiting on ``clock``.

    ``gain`` is the PGA gain (2/3, 1, 2, 4, 8 or 16, full scale +/-6.144 .. +/-0.256 V);
    the default 1 (+/-4.096 V) covers a 3.3 V divider. ``data_rate_sps`` is one of 8, 16,
    32, 64, 128, 250, 475, 860; a reading takes about 1/data rate.
    """

    def __init__(
        self,
        bus: I2CBus,
        *,
        address: int = 0x48,
        gain: float = 1,
        data_rate_sps: int = 128,
        clock: Clock,
    ) -> None:
        self._bus = bus
        self.address = address
        self._clock = clock
        self._pga = pga_code(gain)
        self._dr = data_rate_code(data_rate_sps)
        self._check_identity()

    # -- settings -----------------------------------------------------------------------
    @property
    def gain(self) -> float:
        """The PGA gain (2/3, 1, 2, 4, 8 or 16)."""
        return list(GAIN_FULL_SCALE_V)[self._pga]

    @gain.setter
    def gain(self, gain: float) -> None:
        self._pga = pga_code(gain)

    @property
    def full_scale_v(self) -> float:
        """The +/- full-scale range in volts for the current gain."""
        return list(GAIN_FULL_SCALE_V.values())[self._pga]

    @property
    def data_rate_sps(self) -> int:
        """Conversions per second; a single-shot reading takes about its inverse."""
        return DATA_RATES_SPS[self._dr]

    @data_rate_sps.setter
    def data_rate_sps(self, data_rate_sps: int) -> None:
        self._dr = data_rate_code(data_rate_sps)

    @property
    def conversion_time_s(self) -> float:
        """How long the driver waits before it polls: 1/DR plus the oscillator tolerance."""
        return (1.0 + OSCILLATOR_TOLERANCE) / self.data_rate_sps

    # -- readings -----------------------------------------------------------------------
    def read_raw(self, channel: int) -> int:
        """One single-shot conversion of AIN``channel`` (0..3) against GND, as its code.

        Raises :class:`~engine.drivers.device_errors.ImplausibleReadingError` when the
        config register does not echo what was written or the code is far below GND.
        """
        if not 0 <= channel <= 3:
            raise ValueError(f"ADS1115 channel {channel} is outside 0..3")
        self._write_register(CONFIG, OS | self._config(channel))
        self._clock.sleep(self.conversion_time_s)
        poll_interval_s = OSCILLATOR_TOLERANCE / self.data_rate_sps
        for _ in range(MAX_POLLS):
            config = self._read_register(CONFIG)
            self._check_config(config, channel)
            if config & OS:
                msb, lsb = self._read_bytes(CONVERSION)
                return self._checked_code(word_to_code(msb, lsb))
            self._clock.sleep(poll_interval_s)
        raise DeviceError(
            f"ADS1115 at I2C 0x{self.address:02X}: conversion on AIN{channel} not done "
            f"after {self.conversion_time_s + MAX_POLLS * poll_interval_s:.4f} s "
            f"at {self.data_rate_sps} SPS"
        )

    def read_volts(self, channel: int) -> float:
        """AIN``channel`` (0..3) against GND, in volts (clips at +/- full scale)."""
        return raw_to_volts(self.read_raw(channel), self.full_scale_v)

    # -- helpers ------------------------------------------------------------------------
    def _check_config(self, config: int, channel: int) -> None:
        """The config register echoes what was written (OS aside); anything else is garbled."""
        expected = self._config(channel)
        if config & ~OS != expected:
            raise ImplausibleReadingError(
                chip="ADS1115",
                place=i2c_place(self.address),
                what="config register",
                value=f"0x{config:04X}",
                plausible=f"0x{expected:04X} as written, with or without OS (0x8000)",
            )

    def _checked_code(self, code: int) -> int:
        """``code`` unless a single-ended input cannot give it (far below GND)."""
        lowest = lowest_single_ended_code(self.full_scale_v)
        if code < lowest:
            raise ImplausibleReadingError(
                chip="ADS1115",
                place=i2c_place(self.address),
                what="single-ended conversion code",
                value=str(code),
                plausible=f"{lowest}..{CODE_MAX} at +/-{self.full_scale_v:g} V full scale",
            )
        return code

    def _config(self, channel: int) -> int:
        return (
            (MUX_SINGLE_ENDED | channel) << MUX_SHIFT
            | self._pga << PGA_SHIFT
            | MODE_SINGLE_SHOT
            | self._dr << DR_SHIFT
            | COMP_QUE_DISABLE
        )

    def _check_identity(self) -> None:
        expected = self._config(0)
        try:
            self._write_register(CONFIG, expected)  # OS=0: no conversion starts
            echoed = self._read_register(CONFIG)
        except DeviceError:
            raise
        except OSError as error:
            raise not_found("ADS1115", self.address, error) from error
        if echoed & ~OS != expected:
            raise DeviceError(
                f"ADS1115 at I2C 0x{self.address:02X} failed its identity check: config "
                f"register reads 0x{echoed:04X} after writing 0x{expected:04X}; is another "
                "chip at this address?"
            )

    def _write_register(self, register: int, value: int) -> None:
        self._bus.write_i2c_block_data(self.address, register, [value >> 8, value & 0xFF])

    def _read_bytes(self, register: int) -> tuple[int, int]:
        msb, lsb = self._bus.read_i2c_block_data(self.address, register, 2)
        return msb, lsb

    def _read_register(self, register: int) -> int:
        msb, lsb = self._read_bytes(register)
        return msb << 8 | lsb
