"""The robot's hardware as the engine sees it: config, pollers, services, the simulated vest.

- :mod:`engine.hardware.config`: the robot config (which devices, where, what they feed);
  :mod:`engine.hardware.config_check` its rules, with file:line:column problems.
- :mod:`engine.hardware.managed`: drivers on bus-manager handles, ``/devices/<name>/ok``.
- :mod:`engine.hardware.pollers`: polled devices staged onto the blackboard at their rates.
- :mod:`engine.hardware.services`: LEDs, servos and on-request sensors on the real drivers.
- :mod:`engine.hardware.assembly`: :func:`~engine.hardware.assembly.build_hardware`, the
  bus managers, drivers, pollers and services of one config, on real buses or on the
  simulated vest.
- :mod:`engine.hardware.sim_vest`: :func:`~engine.hardware.sim_vest.build_sim_vest`,
  register-level simulated chips moved by the scenario's world, and fault injection.
- :mod:`engine.hardware.timing`: the branching clock that lets inline polls take their time.
- :mod:`engine.hardware.devices_command`: rows for ``vest devices``.
"""
