"""Running trees: the fixed-rate scheduler, hot reload and the assembled robot."""
