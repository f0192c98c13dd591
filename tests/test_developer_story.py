"""The developer guide's story, run: write a leaf, register it, use it in YAML, test it.

``SayInTurn`` is the example leaf of docs/developer-guide.md, as written there.
"""

from __future__ import annotations

import importlib
import inspect
import json
from collections.abc import Mapping
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.cli import main
from engine.files.problems import LoadError
from engine.loader.tree_file import TreeLoader
from engine.nodes import (
    Condition,
    ListOf,
    NodeRegistry,
    Number,
    Param,
    ServiceAction,
    Status,
    Text,
    builtin_registry,
)
from engine.nodes.context import TreeContext
from engine.services import Job
from engine.testing import TreeHarness
from engine.values.param_problems import CheckContext, ParamIssue

REPO = Path(__file__).resolve().parents[1]
GUIDE = REPO / "docs" / "developer-guide.md"


class SayInTurn(ServiceAction):
    """Say the next phrase of a list, in turn, so praise does not sound repetitive.

    The first phrase the first time, then the second, ..., then the first again.
    RUNNING while speaking; SUCCESS when said; FAILURE when the speech service could not
    say it (the same phrase is tried the next time).
    """

    phrases = Param("phrases", ListOf(Text(), min_items=1), doc="what to say, one phrase per turn")
    volume = Param("volume", Number(0.0, 1.0), None, "0..1; empty: the robot's default volume")

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        phrases = args["phrases"]
        twice = sorted({phrase for phrase in phrases if phrases.count(phrase) > 1})
        if twice:
            return [ParamIssue("phrases", f"{twice[0]!r} is listed twice", "list each phrase once")]
        return []

    def __init__(self, name: str, args: SimpleNamespace, ctx: TreeContext) -> None:
        super().__init__(name, args, ctx)
        self.turn = 0  # kept across rounds: the next phrase to say

    def start(self) -> Job:
        phrase = self.phrases[self.turn % len(self.phrases)]
        return self.ctx.actions.say(phrase, volume=self.volume)

    def finished(self, job: Job) -> Status:
        self.turn += 1  # only a phrase that was said counts
        return Status.SUCCESS


PRAISE_TREE = """\
name: praise
rate_hz: 10
description: Praise each wave, never twice the same way in a row.
root:
  Sequence:
    - OnEvent: {key: /sensors/gesture/last, equals: wave}
    - SayInTurn: {phrases: ["Well done!", "Great waving!", "You did it!"], volume: 0.7}
"""


@pytest.fixture
def registry() -> NodeRegistry:
    registry = builtin_registry()
    registry.add(SayInTurn)
    return registry


@pytest.fixture
def praise_yaml(tmp_path: Path) -> Path:
    path = tmp_path / "praise.yaml"
    path.write_text(PRAISE_TREE, encoding="utf-8")
    return path


def test_the_tree_loader_validates_the_new_node_like_a_built_in_one(
    registry: NodeRegistry, praise_yaml: Path
) -> None:
    loader = TreeLoader(registry, default_catalogue())

    definition = loader.load(praise_yaml)

    leaf = definition.root.children[1]
    assert leaf.type.name == "SayInTurn"
    assert leaf.args == {"phrases": ["Well done!", "Great waving!", "You did it!"], "volume": 0.7}


def test_a_mistake_in_the_new_nodes_parameters_is_a_file_line_column_problem(
    registry: NodeRegistry, tmp_path: Path
) -> None:
    path = tmp_path / "praise.yaml"
    path.write_text(
        "name: praise\n"
        "root:\n"
        "  Sequence:\n"
        "    - SayInTurn: {phrases: [Bravo, Wow, Bravo]}\n"
        "    - SayInTurn: {phrase: [Bravo], volume: loud}\n",
        encoding="utf-8",
    )

    with pytest.raises(LoadError) as raised:
        TreeLoader(registry, default_catalogue()).load(path)

    assert [str(problem) for problem in raised.value.problems] == [
        f"{path}:4:28: 'Bravo' is listed twice (list each phrase once)",
        f"{path}:5:7: SayInTurn needs 'phrases' (what to say, one phrase per turn)",
        f"{path}:5:19: unknown parameter 'phrase' for SayInTurn (did you mean 'phrases'?)",
        f"{path}:5:44: 'volume' must be a number, got 'loud' (write digits, e.g. 3.0)",
    ]


def test_say_in_turn_praises_each_wave_with_the_next_phrase(
    registry: NodeRegistry, praise_yaml: Path
) -> None:
    robot = TreeHarness.from_file(praise_yaml, registry=registry)

    for _ in range(4):
        robot.set("/sensors/gesture/last", "wave")
        robot.advance(1.0)

    assert robot.said == ["Well done!", "Great waving!", "You did it!", "Well done!"]
    assert robot.did("say")[0] == {"text": "Well done!", "volume": 0.7}


def test_say_in_turn_stays_quiet_between_waves(registry: NodeRegistry, praise_yaml: Path) -> None:
    robot = TreeHarness.from_file(praise_yaml, registry=registry)

    robot.advance(3.0)
    robot.set("/sensors/gesture/last", "swipe_left")
    robot.advance(3.0)

    assert robot.said == []


def test_say_in_turn_fails_when_the_speaker_fails_and_tries_the_same_phrase_again(
    registry: NodeRegistry, praise_yaml: Path
) -> None:
    robot = TreeHarness.from_file(praise_yaml, registry=registry)
    robot.set("/sensors/gesture/last", "wave")
    robot.tick()

    robot.services.speech.fail_next = "speaker unplugged"
    robot.set("/sensors/gesture/last", "wave")
    # OnEvent: SUCCESS, SayInTurn: FAILURE -> the tree: FAILURE
    assert robot.tick() == Status.FAILURE
    assert robot.tree.root.children[1].feedback_message == "could not act: speaker unplugged"

    robot.set("/sensors/gesture/last", "wave")
    assert robot.tick() == Status.SUCCESS
    # the phrase the speaker failed is not counted as said; it is said on the next wave
    assert [record.args["text"] for record in robot.failed_actions] == ["Great waving!"]
    assert robot.said == ["Well done!", "Great waving!"]


def test_the_guides_five_line_tree_test_runs(tree_harness: Any) -> None:
    robot = tree_harness(REPO / "trees" / "hug.yaml")
    robot.set("/sensors/force/left_n", 6.0)
    robot.set("/sensors/force/right_n", 6.0)
    robot.advance(1.0)
    assert robot.said == ["I love hugs!"]


def test_vest_nodes_lists_a_node_from_an_installed_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # What `pip install` leaves on sys.path for a package with a "vest.nodes" entry point
    metadata = tmp_path / "vest_story_nodes-1.0.dist-info"
    metadata.mkdir()
    (metadata / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: vest-story-nodes\nVersion: 1.0\n", encoding="utf-8"
    )
    (metadata / "entry_points.txt").write_text(
        f"[vest.nodes]\nSayInTurn = {__name__}:SayInTurn\n", encoding="utf-8"
    )
    monkeypatch.syspath_prepend(str(tmp_path))

    assert main(["nodes", "--format", "json"]) == 0

    listed = {node["name"]: node for node in json.loads(capsys.readouterr().out)}
    node = listed["SayInTurn"]
    assert node["kind"] == "action"
    assert node["source"] == "vest-story-nodes"
    assert node["summary"] == (
        "Say the next phrase of a list, in turn, so praise does not sound repetitive."
    )
    assert node["params"] == [
        {
            "name": "phrases",
            "type": "list of text",
            "required": True,
            "default": None,
            "doc": "what to say, one phrase per turn",
        },
        {
            "name": "volume",
            "type": "number 0..1",
            "required": False,
            "default": None,
            "doc": "0..1; empty: the robot's default volume",
        },
    ]


def test_the_guide_shows_the_code_that_is_tested(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO / "examples" / "plugin"))
    example = importlib.import_module("vest_example_nodes")
    guide = GUIDE.read_text(encoding="utf-8")

    for leaf in (SayInTurn, example.IsWarm, example.Blink):
        assert inspect.getsource(leaf) in guide, (
            f"docs/developer-guide.md no longer shows {leaf.__name__} as it is tested: "
            "copy the class from its source into the guide"
        )


class Shout(Condition):
    """SUCCESS when the room is louder than ``above_db`` (a typed parameter attribute)."""

    above_db = Param("above_db", Number(0.0, 140.0, "dB"), 70.0, "threshold")
    reads = ("/vars/loudness_db",)

    def check(self) -> bool:
        return (self.read("/vars/loudness_db") or 0.0) > self.above_db


def test_a_parameter_declared_as_a_class_attribute_is_the_node_s_typed_value(
    tmp_path: Path,
) -> None:
    registry = builtin_registry()
    node_type = registry.add(Shout)
    assert [p.name for p in node_type.params] == ["above_db"]  # docs and loader see it
    tree = tmp_path / "loud.yaml"
    tree.write_text("rate_hz: 10\nroot:\n  Shout: {above_db: 80}\n")
    robot = TreeHarness.from_file(tree, registry=registry)
    robot.set("/vars/loudness_db", 85.0)
    assert robot.tick() == Status.SUCCESS
    assert robot.tree.root.above_db == 80.0
    assert Shout.above_db.name == "above_db"  # on the class: the declaration


def test_a_parameter_named_like_a_node_attribute_is_refused() -> None:
    class Confused(Condition):
        status = Param("status", Text())

        def check(self) -> bool:
            return True

    with pytest.raises(TypeError, match="cannot be named like an attribute every node has"):
        builtin_registry().add(Confused)
