"""Fuzz tests: generated input from a hostile or unlucky person, thrown at the loaders and
at the running robot on a virtual clock. Each must end in a clean problem with its place
or a clean run: never another exception, never a hang, never a servo beyond its limits.

Hypothesis is derandomized (the same examples on every run, so CI is deterministic) and
the example counts are modest, to keep the suite fast on two cores.
"""

from __future__ import annotations

from hypothesis import HealthCheck, settings

settings.register_profile(
    "vest-fuzz",
    derandomize=True,
    deadline=None,
    max_examples=60,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
    database=None,
)
settings.load_profile("vest-fuzz")
