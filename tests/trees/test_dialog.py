"""dialog: a heard phrase -> the answer from dialogs/default.yaml (paper, sections 4.7-4.8)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.testing import TreeHarness

TREE = Path(__file__).resolve().parents[2] / "trees" / "dialog.yaml"
NAME = "My name is H B S 2"
COLOR = "My favorite color is blue. My vest is blue."
FALLBACK = "Sorry, I did not understand."


@pytest.fixture
def robot(tree_harness: Callable[..., TreeHarness]) -> TreeHarness:
    return tree_harness(TREE)


def hear(robot: TreeHarness, *utterances: str) -> None:
    """Someone says each utterance (all in the same tick), then a second passes."""
    for utterance in utterances:
        robot.set("/speech/heard", utterance)
    robot.advance(1.0)


def test_asked_its_name_the_robot_says_it(robot: TreeHarness) -> None:
    hear(robot, "what is your name")
    assert robot.said == [NAME]


def test_asked_its_favorite_color_the_robot_says_blue(robot: TreeHarness) -> None:
    hear(robot, "what is your favorite color")
    assert robot.said == [COLOR]


def test_asked_the_temperature_it_reads_the_sensor_then_answers_in_fahrenheit(
    robot: TreeHarness,
) -> None:
    robot.world.temperature_c = 22.2
    hear(robot, "what is the temperature")
    assert [record.action for record in robot.actions] == ["read", "say"]
    assert robot.said == ["The temperature is 72 degrees"]


@pytest.mark.parametrize(
    ("utterance", "answer"),
    [
        ("what is you name", NAME),  # a small recognition error
        ("What's your name?", NAME),
        ("who are you", NAME),
        ("which colour do you like", COLOR),
        ("how warm is it", "The temperature is 72 degrees"),
    ],
)
def test_other_ways_of_asking_get_the_same_answer(
    robot: TreeHarness, utterance: str, answer: str
) -> None:
    robot.world.temperature_c = 22.2
    hear(robot, utterance)
    assert robot.said == [answer]


def test_nonsense_gets_the_fallback_answer(robot: TreeHarness) -> None:
    hear(robot, "purple monkey dishwasher")
    assert robot.said == [FALLBACK]


def test_one_question_gets_one_answer_although_it_stays_on_the_blackboard(
    robot: TreeHarness,
) -> None:
    hear(robot, "what is your name")
    robot.advance(5.0)
    assert robot.said == [NAME]


def test_two_questions_heard_in_the_same_tick_are_both_answered_in_order(
    robot: TreeHarness,
) -> None:
    hear(robot, "what is your name", "what is your favorite color")
    assert robot.said == [NAME, COLOR]


def test_an_unplugged_speaker_fails_the_answer(robot: TreeHarness) -> None:
    robot.services.speech.fail_next = "speaker unplugged"
    robot.set("/speech/heard", "what is your name")
    assert robot.tick() == Status.FAILURE
    assert robot.tree.root.tip().feedback_message == "could not answer: speaker unplugged"


def test_a_temperature_sensor_that_cannot_be_read_fails_the_answer(robot: TreeHarness) -> None:
    robot.services.sensors.fail_next = "MCP9808 not answering"
    robot.set("/speech/heard", "what is the temperature")
    assert robot.tick() == Status.FAILURE
    [failed] = robot.failed_actions
    assert (failed.action, failed.args, failed.error) == (
        "read",
        {"sensor": "temperature"},
        "MCP9808 not answering",
    )
    assert robot.did("read") == []


def test_the_robot_asks_back_and_listens_for_the_answer(robot: TreeHarness) -> None:
    hear(robot, "do you like animals")
    hear(robot, "yes, I have a dog")
    assert robot.said == [
        "I love animals. Do you have a pet?",
        "How lovely! Pets are good friends.",
    ]


def test_an_answer_it_cannot_place_gets_the_follow_up_s_otherwise(robot: TreeHarness) -> None:
    hear(robot, "do you like animals")
    hear(robot, "banana")
    assert robot.said[-1] == "I see. Animals are wonderful."


def test_after_the_follow_up_times_out_an_answer_means_nothing(robot: TreeHarness) -> None:
    hear(robot, "do you like animals")
    robot.advance(11.0)  # the follow-up listens for 10 s
    hear(robot, "yes")
    assert robot.said[-1] == FALLBACK


def test_a_question_instead_of_an_answer_is_answered(robot: TreeHarness) -> None:
    hear(robot, "do you like animals")
    hear(robot, "what is your name")
    assert robot.said[-1] == NAME


ASK_NAME = "Did you ask my name?"
SLOWER = "Sorry, can you say that again, a little slower?"
HELP = "You can ask me my name, my favorite color, or how warm it is."


def test_a_question_heard_only_nearly_is_asked_about_and_a_yes_gets_the_answer(
    robot: TreeHarness,
) -> None:
    hear(robot, "what is your aim")  # like "what is your name", which the matcher refuses
    hear(robot, "yes")
    assert robot.said == [ASK_NAME, NAME]


def test_a_no_to_the_robot_s_question_gets_the_first_reprompt(robot: TreeHarness) -> None:
    hear(robot, "what is your aim")
    hear(robot, "no")
    assert robot.said == [ASK_NAME, SLOWER]


def test_an_answer_that_is_neither_yes_nor_no_is_heard_afresh(robot: TreeHarness) -> None:
    hear(robot, "what is your aim")
    hear(robot, "what is your favorite color")
    assert robot.said == [ASK_NAME, COLOR]


def test_the_robot_does_not_ask_the_same_question_twice_in_a_row(robot: TreeHarness) -> None:
    hear(robot, "what is your aim")
    hear(robot, "what is your game")  # like the name again: neither yes nor no
    assert robot.said == [ASK_NAME, SLOWER]


def test_the_answers_the_guide_gives_for_yes_and_no_are_the_default_dialog_s(
    robot: TreeHarness,
) -> None:
    hear(robot, "what is your aim")
    hear(robot, "yes i did")
    hear(robot, "what is your aim")
    hear(robot, "no i did not")
    assert robot.said == [ASK_NAME, NAME, ASK_NAME, SLOWER]


def test_a_yes_to_the_temperature_reads_the_sensor_before_it_answers(
    robot: TreeHarness,
) -> None:
    robot.world.temperature_c = 22.2
    hear(robot, "how worm is it today")
    hear(robot, "yeah")
    assert robot.said == ["Did you ask how warm it is?", "The temperature is 72 degrees"]
    assert [record.action for record in robot.actions] == ["say", "read", "say"]


def test_a_yes_long_after_the_question_means_nothing(robot: TreeHarness) -> None:
    hear(robot, "what is your aim")
    robot.advance(20.0)  # the robot listens for an answer for 8 s
    hear(robot, "yes")
    assert robot.said == [ASK_NAME, SLOWER]  # a miss soon after the question: in other words


def test_after_a_sorry_the_robot_says_it_in_other_words_in_turn(robot: TreeHarness) -> None:
    for _ in range(4):
        hear(robot, "purple monkey dishwasher")
    assert robot.said == [FALLBACK, SLOWER, HELP, SLOWER]


def test_understood_again_the_robot_starts_over_with_its_plain_sorry(robot: TreeHarness) -> None:
    hear(robot, "purple monkey dishwasher")
    hear(robot, "purple monkey dishwasher")
    hear(robot, "what is your name")
    hear(robot, "purple monkey dishwasher")
    assert robot.said == [FALLBACK, SLOWER, NAME, FALLBACK]


def test_a_sorry_long_after_the_last_is_the_plain_sorry_again(robot: TreeHarness) -> None:
    hear(robot, "purple monkey dishwasher")
    robot.advance(61.0)
    hear(robot, "purple monkey dishwasher")
    assert robot.said == [FALLBACK, FALLBACK]
