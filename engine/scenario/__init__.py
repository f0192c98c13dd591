"""Scenarios: the world scripted on a timeline (touch at 1 s, a hug at 3 s, ...)."""
