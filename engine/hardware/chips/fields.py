"""What a chip kind's own config check works with: the device's raw YAML and the checker.

A chip with structured fields (force pads, joints, LEDs, a range sensor's place, gesture
names) checks them in its chip-kind module with these helpers; the generic checker
(:mod:`engine.hardware.config_check`) checks everything every device has.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from engine.files.problems import Problems
from engine.files.yaml_source import YMap, YValue
from engine.hardware.config import ChipSpec
from engine.values.param_problems import CheckContext
from engine.values.params import Param, ParamType


class ConfigChecks(Protocol):
    """The checker's helpers: each adds its problem with the place and returns None."""

    problems: Problems
    ctx: CheckContext

    def convert(self, kind: ParamType[Any], raw: YValue, what: str) -> Any: ...

    def mapping(self, raw: YValue | None, what: str, example: str) -> YMap | None: ...

    def unknown_fields(self, raw: YMap, known: Sequence[str], what: str) -> None: ...

    def fields(
        self, raw: YMap, params: tuple[Param[Any], ...], what: str
    ) -> dict[str, Any] | None: ...


@dataclass(frozen=True)
class ChipFields:
    """One device's entry of the robot config, being checked."""

    checker: ConfigChecks
    name: str
    raw: YMap
    spec: ChipSpec
    options: dict[str, Any] | None = None
    """The driver's options, converted (None when one of them has a problem)."""


def number_text(value: Any) -> Any:
    """A YAML number as the text a fixed set of choices lists (``12`` -> ``"12"``)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return value
    return f"{value:g}" if isinstance(value, float) else str(value)
