"""More events at once than a key keeps: the missed ones are named in a warning.

An event key keeps its last 32 events. Forty questions in one burst get 32 answers, and
OnEvent warns, naming the tree and how many it missed, instead of losing them silently.
"""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.blackboard.events import EVENT_LOG_LENGTH
from engine.clock import VirtualClock
from engine.dialogs.library import DialogLibrary
from engine.loader.tree_file import TreeLoader
from engine.nodes.context import TreeContext
from engine.nodes.registry import default_registry
from engine.services.actions import ActionLog, TreeActions
from engine.services.simulated import simulated_services
from engine.testing import TreeHarness

DIALOG = Path(__file__).resolve().parents[2] / "trees" / "dialog.yaml"


def test_forty_questions_in_one_burst_get_32_answers_and_a_warning_about_8() -> None:
    robot = TreeHarness.from_file(DIALOG)
    for _ in range(40):
        robot.set("/speech/heard", "what is your name")
    robot.advance(10.0)

    assert len(robot.said) == EVENT_LOG_LENGTH
    assert robot.node_warnings == [
        (
            "Sequence/OnEvent",
            "missed 8 events on /speech/heard: more than the 32 a key keeps came before "
            "this node read them",
        )
    ]


def test_questions_one_at_a_time_miss_nothing() -> None:
    robot = TreeHarness.from_file(DIALOG)
    for _ in range(40):
        robot.set("/speech/heard", "what is your name")
        robot.tick()
    assert len(robot.said) == 40
    assert robot.node_warnings == []


def test_a_robot_logs_the_warning_with_the_trees_name(caplog: pytest.LogCaptureFixture) -> None:
    """Outside the harness (vest run), the tree context's default logs it."""
    clock = VirtualClock()
    catalogue = default_catalogue()
    board = Blackboard(catalogue, clock)
    board.reset()
    dialogs = DialogLibrary.from_folder(DIALOG.parents[1] / "dialogs", catalogue)
    definition = TreeLoader(default_registry(), catalogue, dialogs=dialogs).load(DIALOG)
    services = simulated_services(clock)
    tree = definition.build(
        TreeContext(
            tree=definition.name,
            clock=clock,
            blackboard=board,
            actions=TreeActions(services, clock, definition.name, ActionLog()),
            dialogs=dialogs,
        )
    )
    for _ in range(40):
        board.stage_event("/speech/heard", "what is your name")
    board.commit()

    with caplog.at_level(logging.WARNING, logger="vest.tree"):
        tree.tick()

    assert caplog.messages == [
        "dialog: node Sequence/OnEvent: missed 8 events on /speech/heard: more than the 32 a "
        "key keeps came before this node read them"
    ]
