"""The MCP3008 driver against the simulated chip behind a simulated spidev node."""

from __future__ import annotations

import pytest

from engine.drivers.mcp3008 import MCP3008, command_bytes, raw_to_volts
from engine.sim.mcp3008 import SimMCP3008
from engine.sim.spi_bus import SimSpiDev


def decode(answer: list[int]) -> int:
    return (answer[1] & 0x03) << 8 | answer[2]


@pytest.fixture
def chip() -> SimMCP3008:
    return SimMCP3008(vref_v=3.3)


@pytest.fixture
def spi(chip: SimMCP3008) -> SimSpiDev:
    return SimSpiDev(chip, 0, 0)


def test_each_channel_reads_its_own_volts(chip: SimMCP3008, spi: SimSpiDev) -> None:
    adc = MCP3008(spi, vref_v=3.3)
    volts = [0.0, 0.4, 0.8, 1.2, 1.65, 2.0, 2.9, 3.3]
    for channel, value in enumerate(volts):
        chip.set_input_volts(channel, value)
    for channel, value in enumerate(volts):
        assert adc.read_raw(channel) == min(1023, int(1024 * value / 3.3))
        assert adc.read_volts(channel) == pytest.approx(value, abs=1.01 * 3.3 / 1024)


def test_the_driver_sets_a_clock_and_mode_the_chip_accepts(spi: SimSpiDev) -> None:
    assert spi.max_speed_hz == 125_000_000  # a fresh node, as on a Raspberry Pi
    MCP3008(spi)
    assert spi.mode == 0
    assert spi.max_speed_hz == 1_000_000


def test_a_clock_too_fast_for_the_chip_reads_garbage(chip: SimMCP3008, spi: SimSpiDev) -> None:
    chip.set_input_volts(2, 1.65)
    answers = {decode(spi.xfer2(command_bytes(2))) for _ in range(8)}  # at 125 MHz
    assert answers != {512}


def test_missing_start_bit_gets_a_wrong_answer(chip: SimMCP3008, spi: SimSpiDev) -> None:
    spi.max_speed_hz = 1_000_000
    chip.set_input_volts(5, 1.65)
    assert decode(spi.xfer2([0x01, 0x80 | 5 << 4, 0x00])) == 512

    # Without the start bit the chip takes the SGL bit for a late start bit, reads the
    # rest as another request and has not shifted its result out when the frame ends.
    assert decode(spi.xfer2([0x00, 0x80 | 5 << 4, 0x00])) != 512


def test_leading_zeros_before_the_start_bit_are_allowed(chip: SimMCP3008, spi: SimSpiDev) -> None:
    spi.max_speed_hz = 1_000_000
    chip.set_input_volts(7, 3.3)
    # start bit at the end of the first byte's second nibble shifted by eight clocks
    answer = spi.xfer2([0x00, 0x01, 0x80 | 7 << 4, 0x00])
    assert decode(answer[1:]) == 1023


def test_after_the_msb_first_result_the_chip_repeats_it_lsb_first(
    chip: SimMCP3008, spi: SimSpiDev
) -> None:
    spi.max_speed_hz = 1_000_000
    chip.set_input_volts(1, 1.0)
    code = int(1024 * 1.0 / 3.3)
    answer = spi.xfer2([0x01, 0x80 | 1 << 4, 0x00, 0x00, 0x00])
    bits = "".join(f"{byte:08b}" for byte in answer)
    assert int(bits[14:24], 2) == code  # B9..B0
    assert bits[24:33] == f"{code:010b}"[::-1][1:]  # then B1..B9


def test_xfer_releases_chip_select_between_bytes_so_the_request_breaks_up(
    chip: SimMCP3008, spi: SimSpiDev
) -> None:
    spi.max_speed_hz = 1_000_000
    chip.set_input_volts(0, 1.65)
    assert decode(spi.xfer2(command_bytes(0))) == 512
    assert decode(spi.xfer(command_bytes(0))) != 512


def test_differential_pair_reads_the_difference(chip: SimMCP3008, spi: SimSpiDev) -> None:
    spi.max_speed_hz = 1_000_000
    chip.set_input_volts(2, 2.0)
    chip.set_input_volts(3, 1.0)
    # SGL/DIFF = 0, D2..D0 = 010: CH2 = IN+, CH3 = IN-
    assert decode(spi.xfer2([0x01, 0b0010 << 4, 0x00])) == int(1024 * 1.0 / 3.3)
    # D2..D0 = 011: CH2 = IN-, CH3 = IN+, negative reads 0
    assert decode(spi.xfer2([0x01, 0b0011 << 4, 0x00])) == 0


def test_a_closed_node_refuses_transfers(chip: SimMCP3008) -> None:
    spi = SimSpiDev(chip, None, None)
    with pytest.raises(OSError, match="not open"):
        spi.xfer2([1, 0x80, 0])
    spi.open(0, 1)
    assert spi.device == 1
    assert len(spi.xfer2([1, 0x80, 0])) == 3


def test_raw_to_volts_and_range_checks(spi: SimSpiDev) -> None:
    assert raw_to_volts(512, 3.3) == pytest.approx(1.65)
    assert raw_to_volts(0, 5.0) == 0.0
    with pytest.raises(ValueError, match="1024"):
        raw_to_volts(1024, 3.3)
    adc = MCP3008(spi)
    with pytest.raises(ValueError, match="channel 8"):
        adc.read_raw(8)
    with pytest.raises(ValueError, match="VREF"):
        MCP3008(spi, vref_v=0.1)
    with pytest.raises(ValueError, match="clock"):
        MCP3008(spi, max_speed_hz=10_000_000)
