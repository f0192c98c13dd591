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


def heard_in_two_parts(first: str, second: str, pause_s: float) -> list[str]:
    robot = TreeHarness.from_file(DIALOG)
    robot.set("/speech/heard", first)
    robot.advance(pause_s)
    robot.set("/speech/heard", second)
    robot.advance(6.0)
    return robot.said


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
