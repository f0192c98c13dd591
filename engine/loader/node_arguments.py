"""A node's parameters, converted and checked against its node type's declarations."""

from __future__ import annotations

from typing import Any

from engine.files.problems import Mark, Problems
from engine.files.yaml_source import YMap, YScalar, YValue, describe, plain
from engine.loader.substitution import unresolved
from engine.nodes.spec import NodeType
from engine.values.param_problems import CheckContext, ParamProblem, did_you_mean


def node_arguments(
    node_type: NodeType,
    body: YMap | None,
    children_raw: YValue | None,
    mark: Mark,
    problems: Problems,
    ctx: CheckContext,
) -> tuple[dict[str, Any] | None, str, YValue | None]:
    """A node's parameters converted and checked against its type (problems added with
    their places), its display name, and its children as written (``children:`` or
    ``child:`` among the parameters)."""
    structural = {"many": "children", "one": "child"}.get(node_type.children)
    args: dict[str, Any] = {}
    name = node_type.name
    ok = True
    given = dict(body.items()) if body is not None else {}
    key_marks = body.key_marks if body is not None else {}
    if structural and structural in given:
        children_raw = given.pop(structural)
    raw_name = given.pop("name", None)
    if raw_name is not None:
        if isinstance(raw_name, YScalar) and isinstance(raw_name.value, str | int):
            name = str(raw_name.value)
        else:
            problems.add(raw_name.mark, f"'name' must be text, got {describe(raw_name)}")
    known = [p.name for p in node_type.params]
    for key, value in given.items():
        param = node_type.param(key)
        if param is not None and unresolved(value):
            ok = False  # the unknown ${name} is the problem, already reported
            continue
        if param is None:
            options = [*known, "name", *([structural] if structural else [])]
            hint = did_you_mean(key, options) or (f"{node_type.name} takes " + (", ".join(options)))
            problems.add(key_marks[key], f"unknown parameter {key!r} for {node_type.name}", hint)
            ok = False
            continue
        try:
            args[key] = param.type.convert(plain(value), ctx)
        except ParamProblem as problem:
            message = problem.message
            if message.startswith(("must", "needs", "takes", "item")):
                message = f"{key!r} {message}"
            if isinstance(value, YScalar) and value.via is not None:
                # the fix is where the value was written, not where it is used
                parameter, written = value.via
                message = (
                    f"parameter {parameter!r} is used as {node_type.name}.{key} "
                    f"({value.mark}): {message}"
                )
                problems.add(written, message, problem.hint)
            else:
                problems.add(value.mark, message, problem.hint)
            ok = False
    for param in node_type.params:
        if param.name in args or param.name in given:
            continue
        if param.required:
            problems.add(mark, f"{node_type.name} needs {param.name!r}", param.doc or None)
            ok = False
        else:
            args[param.name] = param.default
    if ok and node_type.check is not None:
        for issue in node_type.check(args, ctx):
            where = given[issue.param].mark if issue.param in given else mark
            problems.add(where, issue.message, issue.hint)
            ok = False
    return (args if ok else None), name, children_raw
