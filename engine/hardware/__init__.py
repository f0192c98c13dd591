"""The robot's hardware as the engine sees it: config, pollers, services, the simulated vest.

- :mod:`engine.hardware.config`: the robot config (which devices, where, what they feed),
  validated with file:line:column problems like the trees.
- :mod:`engine.hardware.pollers`: polled devices staged onto the blackboard at their rates.
- :mod:`engine.hardware.services`: LEDs, servos and on-request sensors on the real drivers.
- :mod:`engine.hardware.assembly`: :func:`build_hardware`, the bus managers, drivers,
  pollers and services of one config, on real buses or on the simulated vest.
- :mod:`engine.hardware.sim_vest`: :func:`build_sim_vest`, register-level simulated chips
  moved by the scenario's :class:`~engine.scenario.world.World`.
- :mod:`engine.hardware.devices_command`: rows for ``vest devices``.
"""
