"""Parameters and profiles: ``${name}`` in a tree file replaced by a value.

A tree declares its parameters with defaults under ``params:``; a profile file
(``trees/profiles/child.yaml``) overrides some of them for a kind of session, and a
``Subtree`` node may pass its own. A scalar that is exactly ``${name}`` takes the value
with its type (a number stays a number); inside longer text it is written as text.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from engine.files.problems import LoadError, Mark, Problem, Problems
from engine.files.yaml_source import YList, YMap, YScalar, YValue, describe, load_yaml
from engine.files.yaml_values import plain
from engine.speech.settings import SPEECH_PROFILE_PARAMS, check_speech_params
from engine.values.param_problems import did_you_mean

_REFERENCE = re.compile(r"\$\{([^}]*)\}")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_PROFILE_KEYS = ("profile", "description", "params")
UNRESOLVED: object = type("Unresolved", (), {"__repr__": lambda self: "<unresolved>"})()


def unresolved(value: YValue) -> bool:
    """True when a ``${name}`` in ``value`` could not be replaced (already a problem)."""
    if isinstance(value, YMap):
        return any(unresolved(item) for _, item in value.items())
    if isinstance(value, YList):
        return any(unresolved(item) for item in value)
    return value.value is UNRESOLVED


@dataclass(frozen=True)
class ParamValue:
    """A parameter's value and where it was set."""

    value: YValue
    source: Mark


@dataclass
class Profile:
    """Parameter values for a kind of session (child, adult, ...)."""

    name: str
    params: dict[str, ParamValue] = field(default_factory=dict)
    description: str = ""
    path: Path | None = None


def kind_of(value: YValue) -> str:
    if isinstance(value, YMap):
        return "mapping"
    if isinstance(value, YList):
        return "list"
    scalar = value.value
    if isinstance(scalar, bool):
        return "true/false"
    if isinstance(scalar, int | float):
        return "number"
    return "nothing" if scalar is None else "text"


def read_params(raw: YValue | None, problems: Problems) -> dict[str, ParamValue]:
    """A ``params:`` mapping: names to values."""
    params: dict[str, ParamValue] = {}
    if raw is None:
        return params
    if not isinstance(raw, YMap):
        problems.add(raw.mark, f"'params' must map names to values, got {describe(raw)}")
        return params
    for name, value in raw.items():
        if not _NAME.match(name):
            problems.add(
                raw.key_marks[name],
                f"parameter name {name!r} is not a plain word",
                "use letters, digits and _",
            )
            continue
        params[name] = ParamValue(value, value.mark)
    return params


def check_override(
    name: str, default: ParamValue, given: ParamValue, problems: Problems, where: str
) -> bool:
    """True when ``given`` may replace ``default`` (same kind of value)."""
    expected, got = kind_of(default.value), kind_of(given.value)
    if expected != got and expected != "nothing":
        problems.add(
            given.source,
            f"{where} sets {name!r} to {describe(given.value)}, but the "
            f"tree expects {expected} (default at line {default.source.line})",
        )
        return False
    return True


def substitute(value: YValue, params: dict[str, ParamValue], problems: Problems) -> YValue:
    """``value`` with every ``${name}`` replaced; unknown names are problems."""
    if isinstance(value, YMap):
        return YMap(
            {k: substitute(v, params, problems) for k, v in value.items()},
            value.mark,
            value.key_marks,
        )
    if isinstance(value, YList):
        return YList([substitute(item, params, problems) for item in value], value.mark)
    text = value.value
    if not isinstance(text, str) or "${" not in text:
        return value
    whole = _REFERENCE.fullmatch(text)
    if whole:
        name = whole.group(1).strip()
        found = _lookup(name, value.mark, params, problems)
        if found is None:
            return YScalar(UNRESOLVED, value.mark)
        if isinstance(found, YScalar):
            return YScalar(found.value, value.mark, (name, params[name].source))
        return found

    def replace(match: re.Match[str]) -> str:
        found = _lookup(match.group(1), value.mark, params, problems)
        if found is None:
            return match.group(0)
        if not isinstance(found, YScalar):
            problems.add(
                value.mark,
                f"parameter {match.group(1)!r} is a {kind_of(found)} and cannot go inside text",
            )
            return match.group(0)
        return str(found.value)

    before = len(problems)
    replaced = _REFERENCE.sub(replace, text)
    return YScalar(UNRESOLVED if len(problems) > before else replaced, value.mark)


def _lookup(
    name: str, mark: Mark, params: dict[str, ParamValue], problems: Problems
) -> YValue | None:
    found = params.get(name.strip())
    if found is None:
        hint = did_you_mean(name, list(params)) or (
            "give the tree this setting: under params: at the top of the file, or New "
            "setting in the editor"
        )
        problems.add(mark, f"unknown parameter ${{{name}}}", hint)
        return None
    return found.value


def load_profile(path: Path, shown: str | None = None) -> Profile:
    """Read a profile file; LoadError with every problem."""
    name = shown or str(path)
    document = load_yaml(path, name)
    problems = Problems()
    if not isinstance(document, YMap):
        where = document.mark if document is not None else Mark(name, 1, 1)
        raise LoadError([Problem(where, "a profile is a mapping with 'profile:' and 'params:'")])
    problems.unknown_fields(document.key_marks, _PROFILE_KEYS, "profile")
    profile_name = path.stem
    raw_name = document.get("profile")
    if isinstance(raw_name, YScalar) and isinstance(raw_name.value, str):
        profile_name = raw_name.value
    elif raw_name is not None:
        problems.add(raw_name.mark, f"'profile' must be a name, got {describe(raw_name)}")
    description = document.get("description")
    params = read_params(document.get("params"), problems)
    values = {name: plain(given.value) for name, given in params.items()}
    for name, message, hint in check_speech_params(values):
        problems.add(params[name].source, message, hint)
    if document.get("params") is None:
        problems.add(document.mark, "a profile needs 'params:'", "list the values it changes")
    problems.raise_if_any()
    text = description.value if isinstance(description, YScalar) else ""
    return Profile(profile_name, params, str(text or ""), path)


def undeclared_params(profile: Profile, declared: set[str], trees: str) -> list[Problem]:
    """A problem for each parameter ``profile`` sets that no tree in ``trees`` declares
    (a misspelt name would otherwise be ignored without a word)."""
    return [
        Problem(
            value.source,
            f"no tree in {trees} declares parameter {name!r}",
            did_you_mean(name, sorted(declared)) or "check the spelling",
        )
        for name, value in profile.params.items()
        if name not in declared and name not in SPEECH_PROFILE_PARAMS
    ]
