"""Every bus the engine ships or drives speaks the one bus interface the drivers are written
against (engine.drivers.bus_protocols), so any of them can be handed to any driver."""

from __future__ import annotations

import serial
import smbus2

from engine.clock import VirtualClock
from engine.drivers.bus_protocols import I2CBus, SerialPort, SpiDevice
from engine.drivers.tca9548a import TCA9548A, LockedBus
from engine.sim.i2c_bus import SimI2CBus
from engine.sim.mcp3008 import SimMCP3008
from engine.sim.spi_bus import SimSpiDev


def test_the_real_simulated_and_wrapped_i2c_buses_are_all_smbus2_compatible() -> None:
    simulated = SimI2CBus(VirtualClock())
    locked = LockedBus(simulated)
    channel = TCA9548A(locked, check=False).channel_bus(3)
    for bus in (smbus2.SMBus(), simulated, locked, channel):
        assert isinstance(bus, I2CBus), type(bus).__name__


def test_the_simulated_spi_node_is_spidev_compatible() -> None:
    assert isinstance(SimSpiDev(SimMCP3008(vref_v=3.3), 0, 0), SpiDevice)


def test_a_pyserial_port_is_what_the_maestro_driver_expects() -> None:
    assert isinstance(serial.Serial(), SerialPort)  # not opened: no port given
    assert not isinstance(object(), SerialPort)
