"""Colors by name or ``#RRGGBB``, as fractions 0..1 of red, green and blue."""

from __future__ import annotations

import re

NAMED_COLORS: dict[str, tuple[float, float, float]] = {
    "off": (0.0, 0.0, 0.0),
    "black": (0.0, 0.0, 0.0),
    "white": (1.0, 1.0, 1.0),
    "red": (1.0, 0.0, 0.0),
    "green": (0.0, 1.0, 0.0),
    "blue": (0.0, 0.0, 1.0),
    "yellow": (1.0, 0.8, 0.0),
    "orange": (1.0, 0.4, 0.0),
    "pink": (1.0, 0.125, 0.375),  # an LED's pink needs far less green and blue than a screen's
    "purple": (0.6, 0.0, 1.0),
    "cyan": (0.0, 1.0, 1.0),
    "magenta": (1.0, 0.0, 1.0),
    "warm_white": (1.0, 0.75, 0.45),
}

_HEX = re.compile(r"^#([0-9a-fA-F]{6})$")


def parse_color(text: str) -> tuple[float, float, float]:
    """``"pink"`` or ``"#FF5A8C"`` to (r, g, b) fractions; ValueError naming the value."""
    named = NAMED_COLORS.get(text.strip().lower())
    if named is not None:
        return named
    match = _HEX.match(text.strip())
    if match is None:
        names = ", ".join(NAMED_COLORS)
        raise ValueError(f"unknown color {text!r}: use #RRGGBB or one of {names}")
    value = int(match.group(1), 16)
    return ((value >> 16) / 255.0, ((value >> 8) & 0xFF) / 255.0, (value & 0xFF) / 255.0)
