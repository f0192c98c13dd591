"""What a tree or a scenario names that the robot it runs on does not have.

A tree is checked against the robot config: ``item:`` must be inside the list the robot's
chip writes (the MPR121's 12 pads), touch pads and joints must exist and a move must be
to an angle the servo and the safety envelope allow; a scenario may fail only devices the
robot has, name only its pads and send only remote commands the robot knows. ``vest run``
and ``vest validate`` run these same checks.
"""

from __future__ import annotations

from collections.abc import Iterable

from engine.files.problems import Problem
from engine.hardware.chips import default_chips
from engine.hardware.config import RobotConfig
from engine.hardware.fault_events import check_fault_events
from engine.hardware.touch_pads import name_scenario_pads, robot_pad_names, unknown_pad
from engine.loader.tree_definition import TreeDefinition
from engine.remote_commands import COMMAND_TYPES
from engine.scenario.scenario_file import ScenarioEvent
from engine.values.param_problems import did_you_mean


def list_lengths(config: RobotConfig | None) -> dict[str, int]:
    """How many items each list key holds on this robot (a touch chip's pads); without a
    robot, the chips' default keys."""
    chips = default_chips()
    lengths: dict[str, int] = {}
    if config is None:
        for kind in chips:
            for output, length in kind.list_lengths:
                if kind.spec.outputs.get(output):
                    lengths[kind.spec.outputs[output]] = length
        return lengths
    for device in config.devices.values():
        chip_kind = chips.get(device.chip)
        for output, length in chip_kind.list_lengths if chip_kind is not None else ():
            if output in device.keys:
                lengths[device.keys[output]] = length
    return lengths


def check_items(definition: TreeDefinition, lengths: dict[str, int]) -> list[Problem]:
    """``item:`` beyond the list it picks from (``item: 12`` of 12 pads) would never be
    true: each such node, at its place."""
    problems: list[Problem] = []
    for node in definition.root.walk():
        key, item = node.args.get("key"), node.args.get("item")
        length = lengths.get(key) if isinstance(key, str) else None
        if length is not None and isinstance(item, int) and not 0 <= item < length:
            problems.append(
                Problem(
                    node.mark,
                    f"item {item} is not in {key}, which holds {length} items",
                    f"use an item from 0 to {length - 1}",
                )
            )
    return problems


def check_on_robot(
    definition: TreeDefinition, config: RobotConfig | None, lengths: dict[str, int]
) -> list[Problem]:
    """What a tree names that the robot does not have: list items, touch pads."""
    problems = check_items(definition, lengths)
    if config is not None:
        problems += check_tree_pads(definition, config) + check_joints(definition, config)
    return problems


def check_joints(definition: TreeDefinition, config: RobotConfig) -> list[Problem]:
    """Moves of joints the robot does not have, or to angles its servos or its safety
    envelope will always refuse: each at its node's place."""
    joints = {joint.name: joint for device in config for joint in device.joints}
    problems: list[Problem] = []
    for node in definition.root.walk():
        if not node.type.moves_its_joint:
            continue
        name = str(node.args.get("joint"))
        joint = joints.get(name)
        if joint is None:
            listed = "joints: " + ", ".join(joints) if joints else "this robot has no joints"
            hint = did_you_mean(name, list(joints)) or listed
            problems.append(Problem(node.mark, f"the robot has no joint {name!r}", hint))
            continue
        angle = node.args.get("angle_deg")
        if not isinstance(angle, int | float):
            continue
        low, high = config.safety.joint_limits.get(name, (joint.min_deg, joint.max_deg))
        low, high = max(low, joint.min_deg), min(high, joint.max_deg)
        if not low <= angle <= high:
            why = "its safety limits" if name in config.safety.joint_limits else "its servo"
            problems.append(
                Problem(
                    node.mark,
                    f"{name} to {angle:g} deg would always be refused: {why} allow "
                    f"{low:g}..{high:g} deg",
                    f"choose an angle from {low:g} to {high:g}",
                )
            )
    return problems


def check_tree_pads(definition: TreeDefinition, config: RobotConfig) -> list[Problem]:
    """``OnTouch`` nodes naming pads the robot does not have would never fire: each name,
    at its node's place."""
    names = robot_pad_names(config)
    problems: list[Problem] = []
    for node in definition.root.walk():
        if node.type.name != "OnTouch":
            continue
        for param in ("pads", "except_pads"):
            for name in node.args.get(param) or ():
                if name not in names:
                    problems.append(Problem(node.mark, *unknown_pad(str(name), names, config)))
    return problems


def check_scenario_events(events: Iterable[ScenarioEvent], config: RobotConfig) -> list[Problem]:
    """The scenario's faults name devices of ``config``; its remote commands are of a type
    the robot carries out; a hand is shown only to a simulated camera."""
    problems = check_fault_events(events, config) + name_scenario_pads(events, config)
    for event in events:
        if event.kind == "show_hand" and (config.camera is None or not config.camera.simulated):
            problems.append(
                Problem(
                    event.mark,
                    f"show_hand needs a simulated camera, and {config.path} has "
                    + ("none" if config.camera is None else "a real one"),
                    "run it on a simulated vest whose config does not say camera: none",
                )
            )
        if event.kind == "cloud" and event.value["type"] not in COMMAND_TYPES:
            kind = event.value["type"]
            problems.append(
                Problem(
                    event.mark,
                    f"no remote command type {kind!r}",
                    did_you_mean(kind, COMMAND_TYPES) or "types: " + ", ".join(COMMAND_TYPES),
                )
            )
    return problems
