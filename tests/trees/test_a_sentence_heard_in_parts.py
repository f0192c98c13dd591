"""A child who pauses mid-sentence is heard in two parts; the robot answers the sentence.

"Tell me ... your name": each part alone matches no rule, and the robot said sorry twice.
Now a part not understood alone, heard within a few seconds of one not understood, is
judged joined to it. A part understood alone is answered as before, and a part heard long
after is a new sentence.
"""

from __future__ import annotations

from pathlib import Path

from engine.testing import TreeHarness

DIALOG = Path(__file__).resolve().parents[2] / "trees" / "dialog.yaml"


def heard_in_turn(*utterances: tuple[str, float]) -> list[str]:
    """What the robot said to each utterance, each followed by that many seconds."""
    robot = TreeHarness.from_file(DIALOG)
    for words, then_s in utterances:
        robot.set("/speech/heard", words)
        robot.advance(then_s)
    return robot.said


def heard_in_two_parts(first: str, second: str, pause_s: float) -> list[str]:
    return heard_in_turn((first, pause_s), (second, 6.0))


def test_the_rest_of_a_sentence_is_answered_with_its_start() -> None:
    said = heard_in_two_parts("tell me", "your name", pause_s=3.0)
    assert said == ["Sorry, I did not understand.", "My name is H B S 2"]


def test_the_rest_after_a_question_about_the_start_still_completes_it() -> None:
    # "do you like" is asked about; "puppies" is no yes or no, but the end of the sentence
    said = heard_in_two_parts("do you like", "puppies", pause_s=3.0)
    assert said == ["Did you ask whether I like animals?", "I love animals. Do you have a pet?"]


def test_words_heard_long_after_are_a_sentence_of_their_own() -> None:
    said = heard_in_two_parts("tell me", "your name", pause_s=8.0)
    assert said == [
        "Sorry, I did not understand.",
        "Did you ask my name?",  # "your name" alone, as it always was
    ]


def test_a_part_understood_alone_is_answered_as_it_is() -> None:
    said = heard_in_two_parts("tell me", "how are you", pause_s=3.0)
    assert said == ["Sorry, I did not understand.", "I am fine, thank you!"]


def test_an_unrelated_start_does_not_turn_a_question_into_another_answer() -> None:
    # "how is it" alone is asked about (the temperature); joined to the sentence before
    # it would match "how are you": the robot asks, as it would without the start
    said = heard_in_two_parts("are you a robot", "how is it", pause_s=3.0)
    assert said == ["Sorry, I did not understand.", "Did you ask how warm it is?"]


def test_only_the_part_just_before_is_joined() -> None:
    parts = [(part, 4.5) for part in ("tell me", "and", "so", "well")]  # four sorries
    said = heard_in_turn(*parts, ("your name", 6.0))
    assert said[-1] == "Did you ask my name?"  # not "tell me ... your name"


def test_an_answer_to_the_robot_s_question_said_in_parts_is_answered() -> None:
    # "I love animals. Do you have a pet?" ... "i have" ... "a dog"
    said = heard_in_turn(("do you like dogs", 4.0), ("i have", 2.0), ("a dog", 6.0))
    assert said[-1] == "How lovely! Pets are good friends."


def test_a_yes_after_a_hesitation_and_a_sorry_answers_no_old_question() -> None:
    # "Did you ask my name?" ... "um" gets a sorry: the question has passed
    said = heard_in_turn(("what is your aim", 2.0), ("um", 2.0), ("yes", 2.0))
    assert "My name is H B S 2" not in said
