"""The robot's hardware as the engine sees it: config, pollers, services, the simulated vest.

- :mod:`engine.hardware.config`: the robot config's types (which devices, where, what they
  feed); :mod:`engine.hardware.config_check` its rules, with file:line:column problems;
  :mod:`engine.hardware.config_file` reads a config file through both; buses and the rules
  between devices are in :mod:`~engine.hardware.config_buses` and
  :mod:`~engine.hardware.config_cross_checks`.
- :mod:`engine.hardware.managed_buses`: drivers on bus-manager handles.
- :mod:`engine.hardware.device_health`: ``/devices/<name>/ok``.
- :mod:`engine.hardware.pollers`: polled devices staged onto the blackboard at their rates.
- :mod:`engine.hardware.services`: LEDs, servos and on-request sensors on the real drivers.
- :mod:`engine.hardware.chips`: the chip kinds, one module per chip (spec, field checks,
  probe, poller, simulated model, rules across devices) and their registry.
- :mod:`engine.hardware.assembly`: :func:`~engine.hardware.assembly.build_hardware`, the
  bus managers, drivers, pollers and services of one config (a
  :class:`~engine.hardware.robot_hardware.Hardware`), on the machine's buses
  (:mod:`engine.hardware.real_buses`) or on the simulated vest.
- :mod:`engine.hardware.sim_vest`: :func:`~engine.hardware.sim_vest.build_sim_vest`,
  register-level simulated chips moved by the scenario's world, and fault injection.
- :mod:`engine.hardware.branching_clock`: the clock that lets inline polls take their time.
- :mod:`engine.hardware.device_report`: the rows ``vest devices`` prints.
"""
