"""Say fills {fields} from the blackboard; a field with no value yet fails the action."""

import textwrap

from py_trees.common import Status

from engine.testing import TreeHarness

TREE = """\
    name: weather
    rate_hz: 10
    root:
      Say: {text: "It is {temperature_f:.0f} degrees and {/vars/mood}"}
    """


def test_say_fills_its_fields_from_the_blackboard(tmp_path):
    path = tmp_path / "weather.yaml"
    path.write_text(textwrap.dedent(TREE))
    robot = TreeHarness.from_file(path)
    robot.set("/sensors/temperature/f", 71.96)
    robot.set("/vars/mood", "sunny")
    assert robot.tick() == Status.SUCCESS
    assert robot.said == ["It is 72 degrees and sunny"]


def test_say_fails_when_a_field_has_no_value_yet_and_says_which(tmp_path):
    path = tmp_path / "weather.yaml"
    path.write_text(textwrap.dedent(TREE))
    robot = TreeHarness.from_file(path)
    assert robot.tick() == Status.FAILURE
    assert robot.said == []
    assert "/sensors/temperature/f has no value yet" in robot.tree.root.feedback_message
    assert robot.node_errors == []
