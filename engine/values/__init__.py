"""The project's value language: typed parameters and templates filled from the blackboard.

Tree nodes, robot configs, scenarios, dialogs and remote commands all declare the values
they accept with :mod:`engine.values.params` and check them the same way; nothing here
depends on nodes, dialogs or hardware.
"""
