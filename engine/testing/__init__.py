"""Tick-level testing of YAML trees: a virtual clock and recording fake services.

::

    def test_hug_lights_pink_and_speaks_once(tree_harness):
        robot = tree_harness("trees/hug.yaml")
        robot.set("/sensors/force/left_n", 6.0)
        robot.set("/sensors/force/right_n", 6.0)
        robot.advance(1.0)
        assert robot.said == ["I love hugs!"]
"""

from engine.testing.harness import TreeHarness

__all__ = ["TreeHarness"]
