"""The robot config's device keys: which blackboard key each reading of a device feeds.

A chip names default keys for its readings (``/sensors/touch/any``); a device's ``keys:``
maps readings elsewhere, to a key that holds the same kind of value (or to a /vars/ key).
"""

from __future__ import annotations

from engine.blackboard.catalogue import range_key
from engine.files.yaml_source import YMap, YValue
from engine.hardware.chips.fields import ConfigChecks
from engine.hardware.config import ChipSpec
from engine.values.param_problems import did_you_mean
from engine.values.params import Key


def check_device_keys(
    checker: ConfigChecks, raw: YMap, spec: ChipSpec, side: str | None
) -> dict[str, str] | None:
    """The blackboard keys a device feeds: its chip's defaults, with the device's ``keys:``
    over them (each reading to a key that holds its kind of value); None after a problem."""
    keys = dict(spec.outputs)
    if spec.role == "range" and side is not None:
        keys["range"] = range_key(side)
    section = checker.mapping(raw.get("keys"), "'keys'", "e.g. keys: {any: /sensors/touch/any}")
    ok = True
    if section is not None:
        if not spec.outputs:
            checker.problems.add(
                section.mark,
                f"{spec.chip} feeds no keys of its own here",
                "give each pad its 'key' under 'pads'" if spec.role == "force" else None,
            )
            return None
        for output, value in section.items():
            if output not in spec.outputs:
                checker.problems.add(
                    section.key_marks[output],
                    f"{spec.chip} has no reading {output!r}",
                    did_you_mean(output, list(spec.outputs))
                    or "readings: " + ", ".join(spec.outputs),
                )
                ok = False
                continue
            default = checker.ctx.catalogue.lookup(spec.outputs[output])
            kinds = (default.kind,) if default is not None else ("state",)
            key = checker.convert(Key(kinds=kinds), value, output)
            if key is None or not _same_type(checker, keys.get(output), key, value, output):
                ok = False
            else:
                keys[output] = key
    missing = [output for output, key in keys.items() if not key]
    if missing and spec.role == "range" and side is None:
        return None  # the missing 'side' was reported
    if missing:
        checker.problems.add(raw.mark, f"{spec.chip} needs keys for " + ", ".join(missing))
        return None
    return keys if ok else None


def _same_type(
    checker: ConfigChecks, default: str | None, key: str, raw: YValue, output: str
) -> bool:
    """A reading goes to a key that holds its kind of value (or to any /vars/ key):
    touch's pads (a list) mapped onto /sensors/touch/any (a bool) would never fire."""
    catalogue = checker.ctx.catalogue
    expected = catalogue.lookup(default) if default else None
    target = catalogue.lookup(key)
    if expected is None or target is None or target.value_type is object:
        return True
    if target.value_type is expected.value_type:
        return True
    checker.problems.add(
        raw.mark,
        f"reading {output!r} is a {expected.type_name}, but {key} holds a {target.type_name}",
        f"map it to {default} or to a /vars/ key",
    )
    return False
