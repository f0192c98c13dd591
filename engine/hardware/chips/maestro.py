"""The Pololu Mini Maestro servo controller on a serial port: the robot's joints."""

from __future__ import annotations

from typing import Any

from engine.drivers.servo_joints import MAESTRO_MAX_US, MAESTRO_MIN_US, Joint
from engine.files.yaml_source import YValue, plain
from engine.hardware.chips.fields import ChipFields, number_text
from engine.hardware.chips.kind import ChipKind, SimPlacement
from engine.hardware.config import ChipSpec, DeviceConfig
from engine.values.params import REQUIRED, Choice, Integer, Number, Param

JOINT_FIELDS = (
    Param("channel", Integer(0, 23), REQUIRED, "Maestro channel"),
    Param("min_deg", Number(-360.0, 360.0, "deg"), REQUIRED, "lowest angle"),
    Param("max_deg", Number(-360.0, 360.0, "deg"), REQUIRED, "highest angle"),
    Param("max_speed_dps", Number(0.0, 10_000.0, "deg/s"), REQUIRED, "speed limit"),
    Param("min_us", Number(unit="us"), 1000.0, "pulse width at min_deg, 64..4000 us"),
    Param("max_us", Number(unit="us"), 2000.0, "pulse width at max_deg, 64..4000 us"),
    Param("home_deg", Number(-360.0, 360.0, "deg"), 0.0, "resting angle"),
    Param(
        "rest_speed_dps",
        Number(0.0, 10_000.0, "deg/s"),
        None,
        "speed back to home_deg when a behavior is halted (default: a third of max_speed_dps)",
    ),
)
CHANNEL_COUNTS = ("6", "12", "18", "24")


def _joints_check(fields: ChipFields) -> tuple[Joint, ...] | None:
    section = fields.checker.mapping(
        fields.raw.get("joints"),
        "'joints'",
        "e.g. joints: {neck: {channel: 0, min_deg: -60, max_deg: 60, max_speed_dps: 120}}",
    )
    if section is None:
        if "joints" not in fields.raw:
            fields.checker.problems.add(
                fields.raw.mark,
                f"maestro device {fields.name!r} needs 'joints'",
                "e.g. joints: {neck: {channel: 0, min_deg: -60, max_deg: 60, max_speed_dps: 120}}",
            )
        return None
    channels_raw = fields.raw.get("channels")
    channels = 12
    if channels_raw is not None and number_text(plain(channels_raw)) in CHANNEL_COUNTS:
        channels = int(number_text(plain(channels_raw)))
    joints: list[Joint] = []
    owner: dict[int, str] = {}
    ok = True
    for joint_name, body in section.items():
        joint = _joint(fields, joint_name, body, channels)
        if joint is None:
            ok = False
            continue
        if joint.channel in owner:
            fields.checker.problems.add(
                section.entries[joint_name].mark,
                f"joint {joint_name!r} uses channel {joint.channel}, already used by joint "
                f"{owner[joint.channel]!r}",
                "give each joint its own channel",
            )
            ok = False
        owner[joint.channel] = joint_name
        joints.append(joint)
    if not joints and ok:
        fields.checker.problems.add(section.mark, "'joints' lists no joint")
        ok = False
    return tuple(joints) if ok else None


def _joint(fields: ChipFields, joint_name: str, body: YValue, channels: int) -> Joint | None:
    raw = fields.checker.mapping(
        body, f"joint {joint_name!r}", "e.g. {channel: 0, min_deg: -60, max_deg: 60, ...}"
    )
    if raw is None:
        return None
    fields.checker.unknown_fields(raw, [p.name for p in JOINT_FIELDS], "joint")
    values = fields.checker.fields(raw, JOINT_FIELDS, f"joint {joint_name!r}")
    if values is None:
        return None
    place = raw.entries.get
    problems = fields.checker.problems
    before = len(problems)
    if values["channel"] >= channels:
        problems.add(
            place("channel", raw).mark,
            f"joint {joint_name!r}: channel {values['channel']} is beyond the Maestro's "
            f"{channels} channels (0..{channels - 1})",
        )
    if not values["min_deg"] < values["max_deg"]:
        problems.add(
            place("min_deg", raw).mark,
            f"joint {joint_name!r}: limits inverted, min_deg {values['min_deg']:g} is not "
            f"below max_deg {values['max_deg']:g}",
            "swap them",
        )
    if not 0 < values["min_us"] < values["max_us"]:
        problems.add(
            place("min_us", raw).mark,
            f"joint {joint_name!r}: pulse limits {values['min_us']:g}..{values['max_us']:g} "
            "us are not increasing and positive",
        )
    else:
        for name in ("min_us", "max_us"):
            if not MAESTRO_MIN_US <= values[name] <= MAESTRO_MAX_US:
                problems.add(
                    place(name, raw).mark,
                    f"joint {joint_name!r}: {name} {values[name]:g} us is outside the "
                    f"Maestro's pulse range {MAESTRO_MIN_US:g}..{MAESTRO_MAX_US:g} us "
                    f"({MAESTRO_MIN_US:g} us is its lowest Min setting)",
                    "hobby servos take about 500..2500 us; match the Min and Max set in "
                    "the Maestro Control Center",
                )
    if not values["max_speed_dps"] > 0:
        problems.add(
            place("max_speed_dps", raw).mark,
            f"joint {joint_name!r}: max_speed_dps must be above 0",
        )
    rest = values["rest_speed_dps"]
    if rest is not None and not 0 < rest <= values["max_speed_dps"]:
        problems.add(
            place("rest_speed_dps", raw).mark,
            f"joint {joint_name!r}: rest_speed_dps {rest:g} must be above 0 and at most "
            f"max_speed_dps {values['max_speed_dps']:g}",
        )
    if len(problems) > before:
        return None
    if not values["min_deg"] <= values["home_deg"] <= values["max_deg"]:
        problems.add(
            place("home_deg", raw).mark,
            f"joint {joint_name!r}: home_deg {values['home_deg']:g} is outside its limits "
            f"{values['min_deg']:g}..{values['max_deg']:g}",
        )
        return None
    try:
        return Joint(name=joint_name, **values)
    except ValueError as error:  # e.g. a speed limit the Maestro cannot express
        problems.add(place("max_speed_dps", raw).mark, str(error))
        return None


def _joints(fields: ChipFields) -> dict[str, Any] | None:
    joints = _joints_check(fields)
    return None if joints is None else {"joints": joints}


def _simulate(vest: SimPlacement, device: DeviceConfig) -> None:
    vest.add_maestro(device)


KIND = ChipKind(
    ChipSpec(
        "maestro",
        "Pololu Mini Maestro servo controller (USB serial)",
        "serial",
        "servos",
        options=(
            Param("channels", Choice(("6", "12", "18", "24")), "12", "servo channels"),
            Param("device_number", Integer(0, 127), 12, "Pololu-protocol device number"),
            Param("protocol", Choice(("compact", "pololu")), "compact", "serial protocol"),
        ),
        fields=("joints",),
    ),
    _joints,
    simulate=_simulate,
)
