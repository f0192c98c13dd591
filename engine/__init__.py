"""vest: a behavior-tree driven social interaction engine for robots wearing a sensor vest."""

__version__ = "0.1.0"
