"""RGB LEDs on PCA9685 channels: the robot's face lights.

Colours are (red, green, blue) fractions of full brightness, 0.0..1.0; names and
``#RRGGBB`` are parsed by :func:`engine.colors.parse_color`, shared with the tree loader.
"""

from __future__ import annotations

from collections.abc import Mapping

from engine.colors import parse_color
from engine.drivers.pca9685 import PCA9685
from engine.drivers.pca9685_registers import CHANNELS

Rgb = tuple[float, float, float]

ALL = "all"


def color_to_rgb(color: str) -> Rgb:
    """A colour name (``pink``, ``blue``, ``off``...) or ``#RRGGBB`` as (r, g, b) in 0..1."""
    return parse_color(color)


def _check_rgb(rgb: Rgb) -> Rgb:
    if len(rgb) != 3 or not all(0.0 <= value <= 1.0 for value in rgb):
        raise ValueError(f"an RGB colour is three fractions 0.0..1.0, got {rgb!r}")
    return (float(rgb[0]), float(rgb[1]), float(rgb[2]))


class RgbLeds:
    """Named RGB LEDs, each on three channels (red, green, blue) of one PCA9685.

    ``common_anode``: the LEDs share their anode and each channel sinks current, so a
    channel is lit while its output is low and the duty cycle is inverted.
    """

    def __init__(
        self,
        pwm: PCA9685,
        channels: Mapping[str, tuple[int, int, int]],
        *,
        common_anode: bool = False,
    ) -> None:
        if not channels:
            raise ValueError("RgbLeds needs at least one LED")
        owner: dict[int, str] = {}
        for name, triple in channels.items():
            if name == ALL:
                raise ValueError(f"{ALL!r} names every LED; choose another LED name")
            if len(triple) != 3:
                raise ValueError(f"LED {name!r} needs (red, green, blue) channels, got {triple}")
            for channel in triple:
                if not 0 <= channel < CHANNELS:
                    raise ValueError(
                        f"LED {name!r}: PCA9685 channel must be 0..{CHANNELS - 1}, got {channel}"
                    )
                if channel in owner:
                    raise ValueError(
                        f"LED {name!r}: PCA9685 channel {channel} is already used by "
                        f"LED {owner[channel]!r}"
                    )
                owner[channel] = name
        self._pwm = pwm
        self._channels = dict(channels)
        self.common_anode = common_anode
        self._colors: dict[str, Rgb] = dict.fromkeys(self._channels, (0.0, 0.0, 0.0))

    @property
    def names(self) -> list[str]:
        return list(self._channels)

    def color(self, name: str) -> Rgb:
        """The colour last set on LED ``name``."""
        self._check_name(name)
        return self._colors[name]

    def _check_name(self, name: str) -> None:
        if name not in self._channels:
            known = ", ".join([*self._channels, ALL])
            raise ValueError(f"no LED named {name!r}; the LEDs are {known}")

    def set_color(self, name_or_all: str, rgb: Rgb | str) -> None:
        """Light LED ``name_or_all`` (or every LED, with ``"all"``) in ``rgb``.

        ``rgb`` is (r, g, b) in 0.0..1.0, or anything :func:`color_to_rgb` takes.
        """
        color = color_to_rgb(rgb) if isinstance(rgb, str) else _check_rgb(rgb)
        names = self.names if name_or_all == ALL else [name_or_all]
        for name in names:
            self._check_name(name)
        for name in names:
            for channel, value in zip(self._channels[name], color, strict=True):
                self._pwm.set_duty(channel, 1.0 - value if self.common_anode else value)
            self._colors[name] = color

    def off(self) -> None:
        """Every LED dark."""
        self.set_color(ALL, (0.0, 0.0, 0.0))
