"""Every simulated chip answers its reference driver as the data sheet says.

Adafruit's CircuitPython drivers (pinned in the ``dev`` extra) were written against the
real chips, not against our models: each test runs one of them on the simulated chip
through a ``busio.I2C`` stand-in (``reference_bus.py``) and checks what it reads, or what
the chip holds after it wrote. Simulated time only: the stand-in moves the clock by each
transaction's time on the wire and the drivers' ``time.sleep`` moves it too. A driver
that keeps polling for something the model never does fails with
``TransactionBudgetError`` instead of hanging the run.
"""

from __future__ import annotations

import types
from collections.abc import Callable

import pytest

from engine.clock import VirtualClock
from engine.sim.ads1115 import SimADS1115
from engine.sim.fsr import fsr406_volts
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.mcp9808 import SimMCP9808
from engine.sim.mpr121 import SimMPR121
from engine.sim.pca9685 import SimPCA9685
from engine.sim.vl53l0x import SimVL53L0X

from .reference_bus import NvmOff, ReferenceI2C, TransactionBudgetError, load_reference_driver

Reference = Callable[[str], types.ModuleType]


@pytest.fixture
def i2c(bus: SimI2CBus, clock: VirtualClock) -> ReferenceI2C:
    """CircuitPython's ``busio.I2C`` at its default 100 kHz, over the simulated bus."""
    return ReferenceI2C(bus, clock)


@pytest.fixture
def reference(clock: VirtualClock, monkeypatch: pytest.MonkeyPatch) -> Reference:
    """``reference("adafruit_mcp9808")``: Adafruit's driver module, on the simulated clock."""
    return lambda name: load_reference_driver(name, clock, monkeypatch)


# -- MPR121: the pad a hand touches --------------------------------------------------------------
def test_mpr121_driver_sees_the_pad_the_hand_touches_and_lets_go(
    bus: SimI2CBus, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimMPR121())
    assert isinstance(chip, SimMPR121)
    touch = reference("adafruit_mpr121").MPR121(i2c)
    assert touch.touched_pins == (False,) * 12

    chip.touch(3)
    assert touch[3].value
    assert touch.touched_pins == tuple(pad == 3 for pad in range(12))
    assert touch[3].raw_value == 600 - 40  # the finger pulls the pad's data down

    chip.touch(3, touching=False)
    assert touch.touched() == 0


def test_mpr121_driver_configures_the_thresholds_the_chip_then_holds(
    bus: SimI2CBus, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimMPR121())
    assert isinstance(chip, SimMPR121)
    touch = reference("adafruit_mpr121").MPR121(i2c)  # writes each one in stop mode
    assert [chip.threshold(pad) for pad in range(12)] == [(12, 6)] * 12
    assert chip.running  # and it left the chip scanning all 12 pads

    touch[5].threshold = 50  # firmer than the 40-count touch
    chip.touch(5)
    assert not touch[5].value


# -- ADS1115: the force pads' divider voltage ----------------------------------------------------
def test_ads1115_driver_reads_the_volts_of_the_squeezed_pads(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimADS1115(clock))
    assert isinstance(chip, SimADS1115)
    left_v, right_v = fsr406_volts(6.0), fsr406_volts(0.5)
    chip.set_input_volts(0, left_v)
    chip.set_input_volts(1, right_v)
    ads1x15 = reference("adafruit_ads1x15")
    adc = ads1x15.ADS1115(i2c, gain=1, data_rate=860)  # +/-4.096 V, as in hbs2.yaml
    lsb_v = 4.096 / 32768

    started = clock.now()
    left = ads1x15.AnalogIn(adc, ads1x15.ads1x15.Pin.A0).voltage
    assert clock.now() - started >= 1 / 860  # the driver waited out the conversion
    right = ads1x15.AnalogIn(adc, ads1x15.ads1x15.Pin.A1).voltage

    assert left == pytest.approx(left_v, abs=lsb_v)
    assert right == pytest.approx(right_v, abs=lsb_v)


def test_ads1115_driver_reads_a_negative_difference_between_two_inputs(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimADS1115(clock))
    assert isinstance(chip, SimADS1115)
    chip.set_input_volts(0, 1.0)
    chip.set_input_volts(1, 1.75)
    ads1x15 = reference("adafruit_ads1x15")
    adc = ads1x15.ADS1115(i2c, gain=2)  # +/-2.048 V, 128 SPS
    difference = ads1x15.AnalogIn(adc, ads1x15.ads1x15.Pin.A0, ads1x15.ads1x15.Pin.A1)
    assert difference.voltage == pytest.approx(-0.75, abs=2.048 / 32768)


# -- MCP9808: the room's temperature ------------------------------------------------------------
def test_mcp9808_driver_reads_the_room_temperature_after_a_conversion(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimMCP9808(clock, temperature_c=23.5))
    assert isinstance(chip, SimMCP9808)
    thermometer = reference("adafruit_mcp9808").MCP9808(i2c)  # checks both IDs
    clock.advance(0.25)  # one conversion at the power-on 0.0625 degC resolution
    assert thermometer.temperature == 23.5

    chip.temperature_c = -10.5
    clock.advance(0.25)
    assert thermometer.temperature == -10.5


def test_mcp9808_driver_sets_a_coarser_resolution_and_the_alarm_limits(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimMCP9808(clock, temperature_c=30.3))
    assert isinstance(chip, SimMCP9808)
    thermometer = reference("adafruit_mcp9808").MCP9808(i2c)
    thermometer.resolution = 0  # 0.5 degC, a conversion every 30 ms
    thermometer.critical_temperature = 30
    thermometer.upper_temperature = 35
    clock.advance(0.03)

    assert thermometer.resolution == 0
    assert thermometer.temperature == 30.0  # the chip drops the bits below half a degree
    assert thermometer.critical_temperature == 30.0
    assert thermometer.above_critical and not thermometer.above_upper


# -- PCA9685: the face LEDs' duty cycles --------------------------------------------------------
def test_pca9685_driver_sets_the_frequency_and_duty_cycles_the_chip_outputs(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = bus.attach(SimPCA9685(clock))
    assert isinstance(chip, SimPCA9685)
    pwm = reference("adafruit_pca9685").PCA9685(i2c)
    pwm.frequency = 1000  # sleeps, sets the prescaler, wakes, restarts with auto-increment

    assert chip.prescale == 5  # round(25 MHz / 4096 / 1000 Hz) - 1
    assert chip.frequency_hz == pytest.approx(pwm.frequency)
    pwm.channels[0].duty_cycle = 0x7FFF
    pwm.channels[1].duty_cycle = 0xFFFF
    pwm.channels[2].duty_cycle = 0x4000
    pwm.channels[2].duty_cycle = 0

    assert chip.duty(0) == 0x7FF / 4096  # 16-bit duty, 12 bits kept
    assert chip.duty(1) == 1.0  # the "full on" bit
    assert chip.duty(2) == 0.0  # the "full off" bit
    assert pwm.channels[0].duty_cycle == 0x7FF0


# -- VL53L0X: the distance to whoever is in front ------------------------------------------------
def test_vl53l0x_driver_comes_up_through_sts_nvm_handshake_and_ranges(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = SimVL53L0X(clock, bus)
    sensor = reference("adafruit_vl53l0x").VL53L0X(i2c)  # SPAD info from NVM, tuning, cal

    chip.distance_mm = 432
    started = clock.now()
    assert sensor.range == 432
    assert clock.now() - started >= chip.timing_budget_s
    chip.distance_mm = None
    assert sensor.range == 8190  # the chip's "nothing in range"


def test_vl53l0x_driver_ranges_back_to_back_on_the_chip_model(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    """Adafruit's continuous mode (Pololu's startContinuous) on the chip model that ours
    uses: each reading is the distance of a new measurement, one every timing budget."""
    chip = SimVL53L0X(clock, bus)
    sensor = reference("adafruit_vl53l0x").VL53L0X(i2c)
    sensor.start_continuous()
    for distance in (900, 500, 300):
        chip.distance_mm = distance
        clock.advance(0.1)
        started = clock.now()
        assert sensor.range == distance
        assert clock.now() - started < 0.005  # a measurement was ready: bus time only
    sensor.stop_continuous()  # and a single shot after it, as the driver does
    chip.distance_mm = 700
    assert sensor.range == 700


def test_vl53l0x_driver_enables_the_reference_spads_the_nvm_names(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    chip = SimVL53L0X(clock, bus)  # NVM: 5 aperture SPADs; reference SPAD 13 is bad
    reference("adafruit_vl53l0x").VL53L0X(i2c)
    # Aperture SPADs start at 12: 12, then 14..17 (13 skipped), nothing else.
    assert [chip.peek(0xB0 + i) for i in range(6)] == [0x00, 0xD0, 0x03, 0x00, 0x00, 0x00]
    assert chip.peek(0x01) == 0xE8  # DSS, pre-range and final range after the calibrations
    assert (chip.peek(0x71), chip.peek(0x72)) == (0x02, 0x94)  # the ~33 ms timing budget


def test_a_chip_whose_nvm_never_answers_stops_the_reference_driver_instead_of_hanging(
    bus: SimI2CBus, clock: VirtualClock, i2c: ReferenceI2C, reference: Reference
) -> None:
    NvmOff(clock, bus)
    i2c.max_transactions = 2_000  # Adafruit's driver waits for ever by default
    with pytest.raises(TransactionBudgetError, match=r"more than 2000 .* 0x29"):
        reference("adafruit_vl53l0x").VL53L0X(i2c)
