"""Device drivers, bus managers and the simulated vest.

Drivers speak to an ``smbus2.SMBus``-compatible bus (or a pyserial port) handed to them;
they never open a bus themselves, so the same driver runs on the robot and on the
register-level models in :mod:`engine.drivers.sim`.
"""
