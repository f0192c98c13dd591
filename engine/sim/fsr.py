"""A model of the Interlink FSR 406 force-sensing resistor in a voltage divider.

The curve chosen here (a simulation aid, not a calibration: the robot's real
volts-to-newtons table lives in its config, see
:class:`~engine.drivers.force_calibration.ForceCalibration`):

- Below the actuation force of 0.2 N the sensor is open (its resistance is in the
  megaohms; we treat it as infinite), so the divider reads 0 V.
- From 0.2 N up, the conductance grows linearly with force, i.e. the resistance falls as
  ``R = 6 kOhm*N / F``: 30 kOhm at 0.2 N, 6 kOhm at 1 N, 600 Ohm at 10 N. This follows
  the log-log "typical force curve" of the Interlink FSR 400-series data sheet, which is
  close to 1/F over the 0.2..10 N range the sensor is made for; the real sensor flattens
  above about 10 N and varies +/-10 % or more between parts and mountings.
- The FSR sits between the supply and the output and ``divider_ohm`` between the output
  and ground (the data sheet's figure: output rises with force), so
  ``V = supply * divider / (divider + R)``.
"""

from __future__ import annotations

import math

FSR406_ACTUATION_N = 0.2
FSR406_OHM_NEWTONS = 6_000.0  # R * F along the curve


def fsr406_resistance_ohm(force_n: float) -> float:
    """The modelled FSR 406 resistance in ohms at ``force_n`` newtons (inf below 0.2 N)."""
    if not math.isfinite(force_n) or force_n < 0:
        raise ValueError(f"FSR force {force_n} N must be a finite, non-negative number")
    if force_n < FSR406_ACTUATION_N:
        return math.inf
    return FSR406_OHM_NEWTONS / force_n


def fsr406_volts(force_n: float, *, supply_v: float = 3.3, divider_ohm: float = 10_000) -> float:
    """The divider's output in volts with ``force_n`` newtons on an FSR 406.

    Never decreases as the force grows; 0 V below the 0.2 N actuation force and
    approaching ``supply_v`` under a hard squeeze.
    """
    if not supply_v > 0:
        raise ValueError(f"supply {supply_v} V must be positive")
    if not divider_ohm > 0:
        raise ValueError(f"divider resistor {divider_ohm} ohm must be positive")
    resistance_ohm = fsr406_resistance_ohm(force_n)
    if math.isinf(resistance_ohm):
        return 0.0
    return supply_v * divider_ohm / (divider_ohm + resistance_ohm)
