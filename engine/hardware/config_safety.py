"""The ``safety:`` section of a robot config: the envelope no tree can switch off.

::

    safety:
      arms: [left_arm, right_arm]   # joints the distance and force rules cover
                                    # (default: every joint but the neck)
      still_within_mm: 100          # no arm moves while anything is closer to the chest
      slow_within_mm: 300           # closer than this, arms move at most slow_speed_dps
      slow_speed_dps: 30
      stop_above_n: 12              # a side force above this stops the arms where they are
      when_unsure: refuse           # a range or force sensor offline, stale or implausible
                                    # counts as the worst case: refuse arm moves (or slow)
      max_volume: 0.9               # speech at most this loud (0..1)
      max_brightness: 0.8           # face LEDs at most this bright (0..1)
      joint_limits:                 # narrower than the servos allow, in degrees
        left_arm: [-10, 70]

Each rule is checked on every service call (trees, remote commands, buttons) and by a
watcher between ticks (:mod:`engine.hardware.safety_envelope`). A distance rule needs the
chest's range sensors and the force rule the side force pads: a config that sets a rule
without its sensors is refused (every arm move would be).
"""

from __future__ import annotations

from typing import Any

from engine.files.yaml_source import YList, YMap, describe, plain
from engine.hardware.chips.fields import ConfigChecks
from engine.hardware.config import DeviceConfig, SafetyConfig
from engine.values.param_problems import did_you_mean
from engine.values.params import Choice, Number, Param

OWN_CHECKS = ("arms", "joint_limits")
FIELDS: tuple[Param[Any], ...] = (
    Param("still_within_mm", Number(0.0, 5000.0, "mm"), None, "no arm moves this close"),
    Param("slow_within_mm", Number(0.0, 5000.0, "mm"), None, "slow arm moves this close"),
    Param("slow_speed_dps", Number(0.1, 1000.0, "deg/s"), 20.0, "arm speed near a person"),
    Param("stop_above_n", Number(0.1, 1000.0, "N"), None, "side force that stops the arms"),
    Param(
        "when_unsure",
        Choice(("refuse", "slow")),
        "refuse",
        "arm moves when a sensor a rule reads is offline, stale or implausible: refuse, "
        "or slow (at slow_speed_dps)",
    ),
    Param("max_volume", Number(0.0, 1.0), 1.0, "loudest speech, a fraction 0..1 (0.9: 90 %)"),
    Param(
        "max_brightness", Number(0.0, 1.0), 1.0, "brightest face LEDs, a fraction 0..1 (0.8: 80 %)"
    ),
)
EXAMPLE = "e.g. safety: {still_within_mm: 100, stop_above_n: 12, max_volume: 0.9}"


def check_safety(
    checker: ConfigChecks, document: YMap, devices: dict[str, DeviceConfig]
) -> SafetyConfig | None:
    """The envelope of a config (no rules when the section is absent); None on problems."""
    joints = {joint.name: joint for d in devices.values() for joint in d.joints}
    raw = document.get("safety")
    default_arms = tuple(name for name in joints if name != "neck")
    if raw is None:
        return SafetyConfig(arms=default_arms)
    section = checker.mapping(raw, "'safety'", EXAMPLE)
    if section is None:
        return None
    checker.unknown_fields(section, [*OWN_CHECKS, *(p.name for p in FIELDS)], "safety")
    entries = {key: value for key, value in section.items() if key not in OWN_CHECKS}
    values = checker.fields(YMap(entries, section.mark, section.key_marks), FIELDS, "safety")
    arms = _arms(checker, section, joints, default_arms)
    limits = _joint_limits(checker, section, joints)
    if values is None or arms is None or limits is None:
        return None
    still, slow = values["still_within_mm"], values["slow_within_mm"]
    if still is not None and slow is not None and slow < still:
        checker.problems.add(
            (section.get("slow_within_mm") or section).mark,
            f"slow_within_mm {slow:g} is closer than still_within_mm {still:g}",
            "arms slow down farther out than they stop: slow_within_mm >= still_within_mm",
        )
        return None
    if not _rules_have_sensors(checker, section, values, devices):
        return None
    slowest = min((joints[arm].max_speed_dps for arm in arms), default=None)
    if slow is not None and slowest is not None and values["slow_speed_dps"] > slowest:
        checker.problems.add(
            (section.get("slow_speed_dps") or section).mark,
            f"slow_speed_dps {values['slow_speed_dps']:g} is faster than an arm may move "
            f"({slowest:g} deg/s)",
            f"choose at most {slowest:g}",
        )
        return None
    return SafetyConfig(arms=arms, joint_limits=limits, **values)


def _rules_have_sensors(
    checker: ConfigChecks, section: YMap, values: dict[str, Any], devices: dict[str, DeviceConfig]
) -> bool:
    """A distance rule without a range sensor, or the force rule without a force pad,
    could never be trusted: every arm move would be refused. Each such rule is a problem."""
    ranges = [d for d in devices.values() if d.role == "range" and "range" in d.keys]
    forces = [pad for d in devices.values() if d.role == "force" for pad in d.pads]
    range_sensor = "a range sensor (vl53l0x)"
    needs = {
        "still_within_mm": (range_sensor, ranges, "refused"),
        "slow_within_mm": (range_sensor, ranges, "slow"),
        "stop_above_n": ("a force pad (ads1115 or mcp3008 with pads)", forces, "refused"),
    }
    if values.get("when_unsure") == "slow":
        needs = {rule: (sensor, present, "slow") for rule, (sensor, present, _) in needs.items()}
    fine = True
    for rule, (sensor, present, outcome) in needs.items():
        if values.get(rule) is not None and not present:
            checker.problems.add(
                (section.get(rule) or section).mark,
                f"safety rule {rule} reads {sensor}, and this robot has none: every arm "
                f"move would be {outcome}",
                f"add the sensor under devices:, or remove {rule}",
            )
            fine = False
    return fine


def _unknown_joint(checker: ConfigChecks, item: Any, name: str, joints: dict[str, Any]) -> None:
    checker.problems.add(
        item.mark,
        f"safety names joint {name!r}, which the robot does not have",
        did_you_mean(name, list(joints)) or "joints: " + (", ".join(joints) or "none"),
    )


def _arms(
    checker: ConfigChecks, section: YMap, joints: dict[str, Any], default: tuple[str, ...]
) -> tuple[str, ...] | None:
    raw = section.get("arms")
    if raw is None:
        return default
    if not isinstance(raw, YList):
        checker.problems.add(raw.mark, f"'arms' must be a list, got {describe(raw)}", EXAMPLE)
        return None
    names: list[str] = []
    for item in raw:
        name = str(plain(item))
        if name not in joints:
            _unknown_joint(checker, item, name, joints)
            return None
        names.append(name)
    return tuple(names)


def _joint_limits(
    checker: ConfigChecks, section: YMap, joints: dict[str, Any]
) -> dict[str, tuple[float, float]] | None:
    raw = section.get("joint_limits")
    if raw is None:
        return {}
    limits_section = checker.mapping(raw, "'joint_limits'", "e.g. {left_arm: [-10, 70]}")
    if limits_section is None:
        return None
    limits: dict[str, tuple[float, float]] = {}
    for name, value in limits_section.items():
        where = limits_section.key_marks[name]
        joint = joints.get(name)
        if joint is None:
            _unknown_joint(checker, value, name, joints)
            return None
        pair = plain(value)
        if (
            not isinstance(pair, list)
            or len(pair) != 2
            or any(isinstance(v, bool) or not isinstance(v, int | float) for v in pair)
        ):
            checker.problems.add(
                value.mark,
                f"joint_limits of {name!r} must be [lowest, highest] in degrees, "
                f"got {describe(value)}",
                "e.g. [-10, 70]",
            )
            return None
        if not pair[0] < pair[1]:
            checker.problems.add(
                value.mark,
                f"joint_limits of {name!r}: the lowest angle {pair[0]:g} is not below the "
                f"highest {pair[1]:g}",
                f"write them lowest first: [{min(pair):g}, {max(pair):g}]",
            )
            return None
        low, high = float(pair[0]), float(pair[1])
        if low < joint.min_deg or high > joint.max_deg:
            checker.problems.add(
                where,
                f"joint_limits of {name!r} [{low:g}, {high:g}] reach beyond the servo's "
                f"{joint.min_deg:g}..{joint.max_deg:g} deg",
                "safety limits narrow a joint's range; they cannot widen it",
            )
            return None
        if not low <= joint.home_deg <= high:
            checker.problems.add(
                where,
                f"joint_limits of {name!r} [{low:g}, {high:g}] leave out its home_deg "
                f"{joint.home_deg:g}: a halted behavior could never bring it back to rest",
                "include home_deg in the limits",
            )
            return None
        limits[name] = (low, high)
    return limits
