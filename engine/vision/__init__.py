"""Seeing a hand: the paper's preprocessing and finger-count CNN (section 4.4, table 2)."""
