"""A node type declares what it uses of the robot (the speaker, the face LEDs, the joint
its parameter names, any joint), and the load-time checks read that: a plugin's node that
speaks or moves takes part in the priority check and the robot check as a built-in one."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.cli.robot_checks import check_joints
from engine.hardware.config_file import load_robot_config
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader
from engine.loader.tree_resources import collisions
from engine.nodes import Leaf
from engine.nodes.registry import builtin_registry
from engine.nodes.spec import ITS_JOINT
from engine.services.turns import SPEAKER
from engine.values.params import Param, Text

ROOT = Path(__file__).resolve().parents[1]


class Chirp(Leaf):
    """A plugin's sound: it takes the speaker."""

    uses = (SPEAKER,)


class Wave(Leaf):
    """A plugin's wave of an arm."""

    joint = Param("joint", Text(), "right_arm", "the arm to wave")
    uses = (ITS_JOINT,)


def loaded(tmp_path: Path, name: str, root: str, priority: int = 5) -> TreeDefinition:
    registry = builtin_registry()
    registry.add(Chirp)
    registry.add(Wave)
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"name: {name}\nrate_hz: 10\npriority: {priority}\nroot:\n  {root}\n")
    return TreeLoader(registry, default_catalogue()).load(path)


def test_a_plugin_node_that_speaks_is_named_beside_a_say_of_the_same_priority(
    tmp_path: Path,
) -> None:
    chirp = loaded(tmp_path, "chirp", "Chirp: {}")
    hello = loaded(tmp_path, "hello", "Say: {text: Hello}")
    quiet = loaded(tmp_path, "quiet", "Chirp: {}", priority=7)
    (found,) = collisions([chirp, hello, quiet])  # not the one of another priority
    assert (found.first.name, found.second.name, found.resources) == (
        "chirp",
        "hello",
        ("speaker",),
    )


def test_a_plugin_node_that_moves_a_joint_collides_on_that_joint_alone(tmp_path: Path) -> None:
    wave = loaded(tmp_path, "wave", "Wave: {joint: left_arm}")
    nod = loaded(tmp_path, "nod", "MoveServo: {joint: neck, angle_deg: 10}")
    lift = loaded(tmp_path, "lift", "MoveServo: {joint: left_arm, angle_deg: 10}")
    assert [c.resources for c in collisions([wave, nod, lift])] == [("left_arm joint",)]


def test_a_plugin_node_naming_a_joint_the_robot_lacks_is_named_at_its_place(
    tmp_path: Path,
) -> None:
    wave = loaded(tmp_path, "wave", "Wave: {joint: left_am}")
    robot = load_robot_config(ROOT / "examples" / "robots" / "sim.yaml")
    (problem,) = check_joints(wave, robot)
    assert "the robot has no joint 'left_am'" in str(problem)
    assert "did you mean 'left_arm'?" in str(problem)


def test_a_node_type_cannot_declare_something_the_robot_has_not() -> None:
    class Sing(Leaf):
        uses = ("the choir",)

    registry = builtin_registry()
    with pytest.raises(TypeError, match="Sing uses \\['the choir'\\]: a node uses some of SPEAKER"):
        registry.add(Sing)


def test_a_single_resource_not_in_a_tuple_is_refused_in_words() -> None:
    class Hum(Leaf):
        uses = SPEAKER  # type: ignore[assignment]  # the slip this guards against

    with pytest.raises(TypeError, match=r"Hum uses 'speaker': a tuple of what it uses"):
        builtin_registry().add(Hum)

    class Mute(Leaf):
        uses = None  # type: ignore[assignment]

    with pytest.raises(TypeError, match=r"Mute uses None: a tuple of what it uses"):
        builtin_registry().add(Mute)


def test_a_node_that_moves_its_joint_must_have_a_joint_parameter() -> None:
    class Shrug(Leaf):
        uses = (ITS_JOINT,)

    with pytest.raises(TypeError, match="Shrug uses its joint but has no 'joint' parameter"):
        builtin_registry().add(Shrug)


def test_a_robot_without_joints_names_every_move_it_cannot_make(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "robots" / "sim.yaml").read_text(encoding="utf-8")
    start = text.index("  servos:")
    end = text.index("# The safety envelope")
    armless = tmp_path / "armless.yaml"
    no_arms = (text[:start] + text[end:]).replace("arms: [left_arm, right_arm]", "arms: []")
    armless.write_text(no_arms, encoding="utf-8")
    robot = load_robot_config(armless)
    assert not [joint for device in robot for joint in device.joints]
    (problem,) = check_joints(loaded(tmp_path, "wave", "Wave: {}"), robot)
    assert "the robot has no joint 'right_arm' (this robot has no joints)" in str(problem)


def test_two_remote_command_trees_are_said_to_share_any_joint_in_words(tmp_path: Path) -> None:
    first = loaded(
        tmp_path, "cloud_a", "CarryOut: {command: /vars/cmd, save_result_as: /vars/result}"
    )
    second = loaded(
        tmp_path, "cloud_b", "CarryOut: {command: /vars/cmd, save_result_as: /vars/result}"
    )
    (found,) = collisions([first, second])
    told = found.describe()
    assert "both use any of the joints and the face LEDs and the speaker at priority 5" in told
