"""Device drivers and bus managers (the simulated vest's chips are in :mod:`engine.sim`).

Drivers speak to a bus handed to them (:mod:`engine.drivers.bus_protocols`: an
``smbus2.SMBus``-compatible I2C bus, an ``spidev``-compatible SPI node, a pyserial port);
they never open a bus themselves, so the same driver runs on the robot and on the
register-level models in :mod:`engine.sim`. Their errors, and the readings they
refuse as impossible for their chip, are in :mod:`engine.drivers.device_errors`.

A bus is owned by a :class:`~engine.drivers.bus_manager.BusManager` (queue and worker),
made of :mod:`~engine.drivers.transaction_runner` (one transaction's retries and status),
:mod:`~engine.drivers.bus_policy` (the rules), :mod:`~engine.drivers.device_table`
(claims), :mod:`~engine.drivers.device_stats` (statistics) and
:mod:`~engine.drivers.device_handle` (what a driver holds).
"""
