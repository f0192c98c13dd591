"""Text templates filled from the blackboard: ``"It is {temperature_f:.0f} degrees"``.

A field names a blackboard key (``{/sensors/temperature/f}``) or a key's short alias
(``{temperature_f}``), optionally with a Python format spec after a colon. Templates are
checked when the tree loads and never evaluate code.
"""

from __future__ import annotations

import re
import string
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from engine.values.param_problems import CheckContext, ParamProblem, did_you_mean
from engine.values.params import ParamType, check_key_characters

_FORMATTER = string.Formatter()

_SAMPLES: dict[type, Any] = {float: 1.5, int: 1, bool: True, str: "text"}
"""A value of each key type, formatted with a field's spec at load time to check the spec."""


@dataclass(frozen=True)
class CompiledTemplate:
    """Literal text and the fields to fill: (literal, key or None, format spec)."""

    source: str
    parts: tuple[tuple[str, str | None, str], ...]

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(key for _, key, _ in self.parts if key is not None)

    def fill(self, read: Callable[[str], Any]) -> str:
        """The text with every field filled by ``read(key)``.

        Raises KeyError naming the key when it has no value yet, ValueError when the value
        does not suit the format spec.
        """
        if not self.keys:  # the literal text, with {{ and }} written as { and }
            return "".join(literal for literal, _, _ in self.parts)
        pieces = []
        for literal, key, spec in self.parts:
            pieces.append(literal)
            if key is None:
                continue
            value = read(key)
            if value is None:
                raise KeyError(f"{key} has no value yet")
            try:
                pieces.append(format(value, spec))
            except (TypeError, ValueError) as error:
                raise ValueError(f"cannot format {key}={value!r} as {spec!r}: {error}") from None
        return "".join(pieces)

    def __str__(self) -> str:
        return self.source


def compile_template(text: str, ctx: CheckContext) -> CompiledTemplate:
    """Parse ``text``; raises :class:`ParamProblem` for a bad field or unknown key."""
    try:
        parsed = list(_FORMATTER.parse(text))
    except ValueError as error:
        raise ParamProblem(
            f"bad template {text!r}: {error}", "write {{ and }} for literal braces"
        ) from None
    parts: list[tuple[str, str | None, str]] = []
    for literal, field, spec, conversion in parsed:
        if field is None:
            parts.append((literal, None, ""))
            continue
        if conversion or (spec and ("{" in spec)):
            raise ParamProblem(f"template field {{{field}}} is too complex", "use {key:.1f}")
        key = _resolve(field, ctx)
        if spec:
            _check_spec(field, key, spec, ctx)
        parts.append((literal, key, spec or ""))
    return CompiledTemplate(text, tuple(parts))


MAX_FORMAT_NUMBER = 100
"""The widest width and the longest precision a format spec may ask for: a spec like
``{key:>900000000}`` would take gigabytes at the tick that fills it."""

_NUMBERS = re.compile(r"\d+")


def _check_spec(field: str, key: str, spec: str, ctx: CheckContext) -> None:
    """A format spec that cannot format the key's kind of value is reported now, not at the
    first tick that fills it (keys of any kind, like /vars/, are checked when filled)."""
    for number in _NUMBERS.findall(spec):
        if len(number) > 3 or int(number) > MAX_FORMAT_NUMBER:
            raise ParamProblem(
                f"format {{{field}:{spec}}} asks for {number[:12]}"
                f"{'...' if len(number) > 12 else ''} characters",
                f"widths and precisions go up to {MAX_FORMAT_NUMBER}, e.g. {{{field}:.1f}}",
            )
    key_spec = ctx.catalogue.lookup(key)
    sample = _SAMPLES.get(key_spec.value_type) if key_spec is not None else None
    if sample is None:
        return
    try:
        format(sample, spec)
    except (TypeError, ValueError) as error:
        kind = key_spec.type_name if key_spec is not None else "value"
        raise ParamProblem(
            f"bad format {spec!r} in {{{field}:{spec}}} for a {kind}: {error}",
            "e.g. {temperature_f:.0f} for a whole number, {temperature_f:.1f} for one decimal",
        ) from None


def _resolve(field: str, ctx: CheckContext) -> str:
    if not field:
        raise ParamProblem("empty template field {}", "name a key, e.g. {temperature_f}")
    if field.startswith("/"):
        check_key_characters(field)
        if ctx.catalogue.lookup(field) is None:
            suggestion = ctx.catalogue.suggest(field)
            hint = f"did you mean {suggestion!r}?" if suggestion else None
            raise ParamProblem(f"unknown blackboard key {field!r} in template", hint)
        return field
    spec = ctx.catalogue.by_alias(field)
    if spec is None:
        aliases = [s.alias for s in ctx.catalogue if s.alias]
        raise ParamProblem(
            f"unknown template field {{{field}}}",
            did_you_mean(field, aliases) or "name a blackboard key, e.g. {/vars/name}",
        )
    return spec.name


class Template(ParamType[CompiledTemplate]):
    """Text that may contain ``{key}`` fields filled from the blackboard when used."""

    name = "text with {fields}"

    def __init__(self, *, max_chars: int | None = None) -> None:
        self.max_chars = max_chars

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": ["string", "number"]}
        if self.max_chars is not None:
            schema["maxLength"] = self.max_chars
        return schema

    def describe(self) -> str:
        return self.name + (f", up to {self.max_chars} characters" if self.max_chars else "")

    def convert(self, value: Any, ctx: CheckContext) -> CompiledTemplate:
        if isinstance(value, bool) or value is None or isinstance(value, dict | list):
            raise ParamProblem("must be text", "put the text in quotes")
        text = str(value)
        if self.max_chars is not None and len(text) > self.max_chars:
            raise ParamProblem(
                f"is {len(text)} characters long, more than {self.max_chars}",
                "say it in several shorter parts",
            )
        return compile_template(text, ctx)
