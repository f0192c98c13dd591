"""The one way a settings file's fields are checked: declared :class:`Param` s read from YAML.

Every file a person writes besides trees (robot configs and their chips, scenarios, button
boards, site and consent records, dialogs) declares its fields as :class:`Param` s, the same
declarations nodes use, and reads them here. Each problem is added to :class:`Problems` at
the value's ``file:line:column`` with the type's hint, so a person fixes them all at once.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from engine.files.problems import Problems
from engine.files.yaml_values import YMap, YValue, describe, plain
from engine.values.param_problems import CheckContext, ParamProblem
from engine.values.params import Param, ParamType


def converted(
    kind: ParamType[Any], raw: YValue, what: str, ctx: CheckContext, problems: Problems
) -> Any:
    """``raw`` as ``kind`` converts it, or None after adding the problem at its place.

    ``what`` names the field in the message (``'rate_hz' must be a number, got 'fast'``).
    """
    try:
        return kind.convert(plain(raw), ctx)
    except ParamProblem as problem:
        problems.add(raw.mark, f"{what!r} {problem.message}", problem.hint)
        return None


def declared_fields(
    raw: YMap, params: Sequence[Param[Any]], what: str, ctx: CheckContext, problems: Problems
) -> dict[str, Any] | None:
    """Every declared field of ``raw``: converted (in the file's order), or its default.

    A required field that is absent is a problem at the mapping (``what`` names it: "camera
    needs 'model'"). Fields ``raw`` has beyond ``params`` are not looked at: a caller whose
    mapping has fields of its own checks them apart. None when any field has a problem.
    """
    declared = {param.name: param for param in params}
    values: dict[str, Any] = {}
    before = len(problems)  # a value may well convert to None (null for "any value")
    for name, value in raw.items():  # in the file's order: what a recording of them shows
        if name in declared:
            values[name] = converted(declared[name].type, value, name, ctx, problems)
    for param in params:
        if param.name in values:
            continue
        if param.required:
            problems.add(raw.mark, f"{what} needs {param.name!r}", param.doc or None)
        else:
            values[param.name] = param.default
    return values if len(problems) == before else None


def settings(
    raw: YValue, params: Sequence[Param[Any]], what: str, ctx: CheckContext, problems: Problems
) -> dict[str, Any] | None:
    """A mapping of exactly the declared fields: unknown ones are problems, with the nearest
    known name as the hint; a value that is not a mapping is one too. None on any problem."""
    if not isinstance(raw, YMap):
        names = ", ".join(p.name for p in params)
        problems.add(raw.mark, f"{what} takes a mapping of {names}, got {describe(raw)}")
        return None
    known = problems.unknown_fields(raw.key_marks, [p.name for p in params], what)
    values = declared_fields(raw, params, what, ctx, problems)
    return values if known else None
