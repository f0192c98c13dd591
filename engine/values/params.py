"""Parameter types of node declarations: each converts a YAML value or says what is wrong.

A conversion problem raises :class:`ParamProblem` with a message that names the expected
type and the value found, and a hint where one helps. The loader adds the place.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Generic, Literal, TypeVar, overload

from engine.values.param_problems import CheckContext, ParamProblem, did_you_mean, shown

T = TypeVar("T")


class ParamType(Generic[T]):
    """Base of parameter types: ``convert`` turns a YAML value into a ``T`` (or raises
    :class:`ParamProblem`). ``name`` is what docs and messages call the type."""

    name = "value"

    def convert(self, value: Any, ctx: CheckContext) -> T:
        return value  # type: ignore[no-any-return]

    def describe(self) -> str:
        return self.name

    def json_schema(self) -> dict[str, Any]:
        """The JSON Schema of a valid value (for editors; the loader's checks are stricter)."""
        return {}


class Text(ParamType[str]):
    name = "text"

    def json_schema(self) -> dict[str, Any]:
        return {"type": ["string", "number"]}

    def convert(self, value: Any, ctx: CheckContext) -> str:
        if isinstance(value, bool) or value is None or isinstance(value, dict | list):
            raise ParamProblem(f"must be text, got {shown(value)}", "put the text in quotes")
        return str(value)


@dataclass(frozen=True)
class Number(ParamType[float]):
    """A real number, optionally bounded (inclusive), with a unit for docs."""

    minimum: float | None = None
    maximum: float | None = None
    unit: str = ""
    name = "number"

    def convert(self, value: Any, ctx: CheckContext) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParamProblem(f"must be a number, got {shown(value)}", self._example())
        try:
            number = float(value)
        except OverflowError:
            raise ParamProblem(
                f"must be a number below 1e308, got one with {int(value).bit_length()} binary"
                " digits",
                self._example(),
            ) from None
        if not math.isfinite(number):
            raise ParamProblem(f"must be a finite number, got {number}", self._example())
        if self.minimum is not None and number < self.minimum:
            raise ParamProblem(f"must be at least {self.minimum:g}, got {number:g}")
        if self.maximum is not None and number > self.maximum:
            raise ParamProblem(f"must be at most {self.maximum:g}, got {number:g}")
        return number

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": "number"}
        if self.minimum is not None:
            schema["minimum"] = self.minimum
        if self.maximum is not None:
            schema["maximum"] = self.maximum
        return schema

    def _example(self) -> str:
        return "write digits, e.g. 3.0" + (f" ({self.unit})" if self.unit else "")

    def describe(self) -> str:
        bounds = ""
        if self.minimum is not None or self.maximum is not None:
            low = "" if self.minimum is None else f"{self.minimum:g}"
            high = "" if self.maximum is None else f"{self.maximum:g}"
            bounds = f" {low}..{high}"
        return f"number{bounds}" + (f" {self.unit}" if self.unit else "")


@dataclass(frozen=True)
class Integer(ParamType[int]):
    minimum: int | None = None
    maximum: int | None = None
    name = "integer"

    def convert(self, value: Any, ctx: CheckContext) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ParamProblem(f"must be a whole number, got {shown(value)}")
        if self.minimum is not None and value < self.minimum:
            raise ParamProblem(f"must be at least {self.minimum}, got {value}")
        if self.maximum is not None and value > self.maximum:
            raise ParamProblem(f"must be at most {self.maximum}, got {value}")
        return value

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": "integer"}
        if self.minimum is not None:
            schema["minimum"] = self.minimum
        if self.maximum is not None:
            schema["maximum"] = self.maximum
        return schema

    def describe(self) -> str:
        if self.minimum is None and self.maximum is None:
            return "integer"
        low = "" if self.minimum is None else str(self.minimum)
        high = "" if self.maximum is None else str(self.maximum)
        return f"integer {low}..{high}"


class Boolean(ParamType[bool]):
    name = "true/false"

    def json_schema(self) -> dict[str, Any]:
        return {"type": "boolean"}

    def convert(self, value: Any, ctx: CheckContext) -> bool:
        if not isinstance(value, bool):
            raise ParamProblem(f"must be true or false, got {shown(value)}")
        return value


@dataclass(frozen=True)
class Choice(ParamType[str]):
    options: tuple[str, ...]
    name = "choice"

    def convert(self, value: Any, ctx: CheckContext) -> str:
        if not isinstance(value, str) or value not in self.options:
            hint = did_you_mean(str(value), self.options) if isinstance(value, str) else None
            options = ", ".join(self.options)
            raise ParamProblem(f"must be one of {options}; got {shown(value)}", hint)
        return value

    def describe(self) -> str:
        return " | ".join(self.options)

    def json_schema(self) -> dict[str, Any]:
        return {"enum": list(self.options)}


_KEY_CHARACTERS = re.compile(r"[A-Za-z0-9_/]+")


def check_key_characters(key: str) -> None:
    """Raise :class:`ParamProblem` when ``key`` has a character other than letters, digits,
    ``_`` and ``/`` (py_trees would read a ``.`` as attribute access at every tick)."""
    if _KEY_CHARACTERS.fullmatch(key) is None:
        bad = next(char for char in key if not _KEY_CHARACTERS.fullmatch(char))
        if bad == "*":
            hint = "write one name in place of '*' (see `vest keys`)"
        else:
            hint = f"e.g. {re.sub(r'[^A-Za-z0-9_/]', '_', key)!r}"
        raise ParamProblem(
            f"blackboard key {key!r} has {bad!r}: keys use only letters, digits, '_' and '/'",
            hint,
        )


@dataclass(frozen=True)
class Key(ParamType[str]):
    """A blackboard key from the catalogue.

    ``access`` says whether the node reads or writes it (the loader lists it so), ``kinds``
    which kinds of key are allowed: a state key is read every tick, an event key is
    reacted to once per event.
    """

    access: Literal["read", "write"] = "read"
    kinds: tuple[str, ...] = ("state",)
    name = "blackboard key"

    def convert(self, value: Any, ctx: CheckContext) -> str:
        if not isinstance(value, str):
            raise ParamProblem(
                f"must be a blackboard key like /sensors/touch/any, got {shown(value)}"
            )
        if not value.startswith("/"):
            raise ParamProblem(
                f"blackboard keys start with '/', got {value!r}",
                f"did you mean {'/' + value!r}?",
            )
        check_key_characters(value)
        spec = ctx.catalogue.lookup(value)
        if spec is None:
            suggestion = ctx.catalogue.suggest(value)
            hint = (
                f"did you mean {suggestion!r}?"
                if suggestion
                else "see `vest keys`; use /vars/NAME for a variable (shared by all trees)"
            )
            raise ParamProblem(f"unknown blackboard key {value!r}", hint)
        if spec.kind == "event" and "event" not in self.kinds:
            raise ParamProblem(
                f"{value!r} is an event key: its value stays after the event",
                "use OnEvent to react once per event",
            )
        if spec.kind == "state" and "state" not in self.kinds:
            if value.startswith("/vars/"):  # a variable is a value, never a stream of events
                raise ParamProblem(
                    f"{value!r} is a tree variable, not an event key",
                    "use Check to compare a /vars/ value each tick",
                )
            raise ParamProblem(
                f"{value!r} is not an event key", "use Check to compare a value each tick"
            )
        if self.access == "write" and not value.startswith("/vars/"):
            raise ParamProblem(
                f"trees may only write variables (/vars/...), not {value!r}",
                "write to /vars/NAME",
            )
        return value

    def json_schema(self) -> dict[str, Any]:
        return {"type": "string", "pattern": "^/"}

    def describe(self) -> str:
        kind = "event key" if self.kinds == ("event",) else "blackboard key"
        return f"{kind} ({self.access})"


@dataclass(frozen=True)
class ListOf(ParamType[list[Any]]):
    item: ParamType[Any]
    min_items: int = 0
    max_items: int | None = None
    name = "list"

    def convert(self, value: Any, ctx: CheckContext) -> list[Any]:
        if not isinstance(value, list):
            raise ParamProblem(f"must be a list like [a, b], got {shown(value)}")
        if len(value) < self.min_items:
            raise ParamProblem(f"needs at least {self.min_items} items, got {len(value)}")
        if self.max_items is not None and len(value) > self.max_items:
            raise ParamProblem(f"takes at most {self.max_items} items, got {len(value)}")
        converted = []
        for index, item in enumerate(value):
            try:
                converted.append(self.item.convert(item, ctx))
            except ParamProblem as problem:
                raise ParamProblem(f"item {index + 1} {problem.message}", problem.hint) from None
        return converted

    def describe(self) -> str:
        return f"list of {self.item.describe()}"

    def json_schema(self) -> dict[str, Any]:
        schema: dict[str, Any] = {"type": "array", "items": self.item.json_schema()}
        if self.min_items:
            schema["minItems"] = self.min_items
        if self.max_items is not None:
            schema["maxItems"] = self.max_items
        return schema


class Scalar(ParamType[Any]):
    """A number, text, or true/false (what a key is compared with)."""

    name = "number, text or true/false"

    def json_schema(self) -> dict[str, Any]:
        return {"type": ["string", "number", "boolean"]}

    def convert(self, value: Any, ctx: CheckContext) -> Any:
        if isinstance(value, dict | list) or value is None:
            raise ParamProblem(f"must be a number, text or true/false, got {shown(value)}")
        return value


class AnyValue(ParamType[Any]):
    """Any YAML value (number, text, list, mapping)."""

    name = "any value"


REQUIRED: Any = object()


class Param(Generic[T]):
    """One declared parameter: its name, type, default (or :data:`REQUIRED`) and meaning.

    Declared as a class attribute of a leaf, it is also how the node reads its value:
    ``volume = Param("volume", Number(0.0, 1.0), None, "0..1")`` makes ``self.volume`` the
    converted value, a ``float | None`` to a type checker (``float`` without the None
    default). The loader, ``vest nodes``, the docs and the JSON Schema come from the same
    declaration.
    """

    @overload
    def __init__(
        self: Param[T], name: str, type: ParamType[T], default: T = ..., doc: str = ""
    ) -> None: ...

    @overload
    def __init__(
        self: Param[T | None], name: str, type: ParamType[T], default: None, doc: str = ""
    ) -> None: ...

    def __init__(
        self, name: str, type: ParamType[Any], default: Any = REQUIRED, doc: str = ""
    ) -> None:
        self.name = name
        self.type = type
        self.default = default
        self.doc = doc

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def __set_name__(self, owner: type, attribute: str) -> None:
        if attribute != self.name:
            raise TypeError(
                f"{owner.__name__}.{attribute} declares Param({self.name!r}): give it its "
                "attribute's name"
            )

    @overload
    def __get__(self, node: None, owner: type) -> Param[T]: ...

    @overload
    def __get__(self, node: object, owner: type) -> T: ...

    def __get__(self, node: object | None, owner: type) -> Param[T] | T:
        if node is None:
            return self  # on the class: the declaration
        return getattr(node.args, self.name)  # type: ignore[attr-defined, no-any-return]


SECONDS = Number(0.0, 86_400.0, "s")
"""A duration or a rest: up to a day (a longer one is a typo, and would never end a test)."""
RATE_HZ = Number(0.1, 1000.0, "Hz")
"""How often something ticks or polls: from once in ten seconds to a thousand times a second."""
SPEED_DPS = Number(0.0, 10_000.0, "deg/s")
"""A turning speed (each joint's own limit applies too)."""
DISTANCE_MM = Number(0.0, 100_000.0, "mm")
"""A distance up to 100 m."""
