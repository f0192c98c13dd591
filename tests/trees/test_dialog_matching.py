"""Matching on words, not characters: the robot answers the question asked, or says it
did not understand. A wrong answer to a child is worse than none."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import load_dialog
from engine.dialogs.model import Dialog
from engine.dialogs.words import same_word

DEFAULT = Path(__file__).resolve().parents[2] / "dialogs" / "default.yaml"


@pytest.fixture(scope="module")
def dialog() -> Dialog:
    return load_dialog(DEFAULT, default_catalogue())


def rule_for(dialog: Dialog, utterance: str) -> str | None:
    match = dialog.match(utterance)
    return match.rule.id if match is not None else None


@pytest.mark.parametrize(
    ("utterance", "rule"),
    [
        ("what is your name", "name"),
        ("What's your name?", "name"),
        ("hey robot, what is your name please", "name"),
        ("who are you", "name"),
        ("what are you called", "name"),
        ("which colour do you like", "color"),
        ("what colors do you like", "color"),
        ("what is your favourite color", "color"),
        ("what's the temperature", "temperature"),
        ("is it cold in here", "temperature"),
        ("is it cold today", "temperature"),
        ("hello", "greeting"),
        ("how are you", "how_are_you"),
        ("do you like animals", "pets"),
        ("do you like dogs", "pets"),
    ],
)
def test_the_ways_of_asking_in_the_dialog_are_understood(
    dialog: Dialog, utterance: str, rule: str
) -> None:
    assert rule_for(dialog, utterance) == rule


@pytest.mark.parametrize(
    "utterance",
    [
        "do you like cake",  # not "do you like animals"
        "what is your favorite food",  # not the color answer
        "how old are you",  # not "how are you"
        "who are your parents",  # not "who are you"
        "what time is it",
        "what is the weather like tomorrow",
        "can you dance",
        "tell me a story",
        "",
        "um",
    ],
)
def test_questions_the_dialog_does_not_answer_get_no_rule(dialog: Dialog, utterance: str) -> None:
    assert rule_for(dialog, utterance) is None


def test_a_question_that_asks_two_things_is_not_half_answered(dialog: Dialog) -> None:
    assert dialog.judge("what is your name and your favorite color").match is None


@pytest.mark.parametrize(
    "utterance",
    [
        "what is my name",  # someone else's
        "what is her name",
        "what is your dog's name",
        "what is my favorite color",
        "which color do you not like",  # turned around
        "I do not like animals",
        "how warm is the water",  # not the room
        "how hot is the oven",
        "i do not know your name",
    ],
)
def test_a_question_about_someone_or_something_else_is_not_answered(
    dialog: Dialog, utterance: str
) -> None:
    assert rule_for(dialog, utterance) is None


@pytest.mark.parametrize("answer", ["my dog died", "i never had a dog", "sure not", "no i do"])
def test_a_reply_that_turns_the_answer_around_is_not_taken_for_yes_or_no(
    dialog: Dialog, answer: str
) -> None:
    pets = next(rule for rule in dialog.rules if rule.id == "pets")
    assert dialog.judge(answer, pets.follow_up).match is None


def test_the_verdict_says_why_nothing_matched(dialog: Dialog) -> None:
    assert "meaning words" in dialog.judge("do you like cake").reason


def test_a_small_slip_in_a_long_word_is_forgiven(dialog: Dialog) -> None:
    assert rule_for(dialog, "what is the temprature") == "temperature"


def test_follow_up_answers_are_tried_first_while_the_robot_listens(dialog: Dialog) -> None:
    pets = next(rule for rule in dialog.rules if rule.id == "pets")
    asked = pets.follow_up
    assert asked is not None
    assert dialog.judge("yes I have a dog", asked).match.rule.id == "has_pet"  # type: ignore[union-attr]
    assert dialog.judge("no", asked).match.rule.id == "no_pet"  # type: ignore[union-attr]
    assert dialog.judge("I do not", asked).match.rule.id == "no_pet"  # type: ignore[union-attr]
    # a child who asks something else instead is answered
    assert dialog.judge("what is your name", asked).match.rule.id == "name"  # type: ignore[union-attr]
    # outside the follow-up, "yes" means nothing
    assert dialog.match("yes") is None


def test_the_recognizer_vocabulary_holds_the_follow_up_phrases(dialog: Dialog) -> None:
    assert "i have a dog" in dialog.phrases
    assert "nope" in dialog.phrases


READING = """
dialog: reading
rules:
  - {id: digits, hear: ["one nine three four"], say: "1934"}
  - {id: other_digits, hear: ["four nine one three"], say: "4913"}
  - {id: doing_now, hear: ["that is what i am doing now"], say: "Good."}
  - {id: doing_it_for, hear: ["what am i doing it for"], say: "For fun."}
"""


def test_a_phrase_said_word_for_word_is_its_rule_s_whatever_else_it_fits(
    tmp_path: Path,
) -> None:
    path = tmp_path / "reading.yaml"
    path.write_text(READING, encoding="utf-8")
    reading = load_dialog(path, default_catalogue())
    assert rule_for(reading, "One, nine, three, four.") == "digits"
    assert rule_for(reading, "four nine one three") == "other_digits"
    assert rule_for(reading, "That's what I'm doing now") == "doing_now"
    # numbers in another order are neither's
    assert rule_for(reading, "nine one four three") is None
    assert rule_for(reading, "one nine three") is None


COMPOUNDS = """
dialog: compounds
rules:
  - {id: bye, hear: ["goodbye"], say: "Bye!"}
  - {id: sport, hear: ["do you like football"], say: "I like football."}
  - {id: treat, hear: ["i want ice cream"], say: "Me too."}
"""


@pytest.mark.parametrize(
    ("written_by_a_recognizer", "rule"),
    [
        ("Good-bye.", "bye"),
        ("Good bye!", "bye"),
        ("Do you like foot ball?", "sport"),
        ("I want icecream", "treat"),
        ("I want ice-cream.", "treat"),
        ("Do you like foot?", None),  # half a compound is not the word
    ],
)
def test_a_compound_written_the_recognizer_s_way_is_the_phrase_s_word(
    tmp_path: Path, written_by_a_recognizer: str, rule: str | None
) -> None:
    path = tmp_path / "compounds.yaml"
    path.write_text(COMPOUNDS, encoding="utf-8")
    assert rule_for(load_dialog(path, default_catalogue()), written_by_a_recognizer) == rule


def test_a_question_word_the_phrase_does_not_have_means_something_else(
    dialog: Dialog, tmp_path: Path
) -> None:
    assert rule_for(dialog, "what pets do you like") is None  # not "do you like ~pet"
    assert rule_for(dialog, "which color do you like") == "color"  # the phrase's own
    path = tmp_path / "reading.yaml"
    path.write_text(
        'dialog: reading\nrules:\n  - {id: too, hear: ["do you like it too"], say: "Yes."}\n',
        encoding="utf-8",
    )
    assert rule_for(load_dialog(path, default_catalogue()), "You may do what you like.") is None


@pytest.mark.parametrize(
    ("one", "other"),
    [
        ("incorrect", "correct"),
        ("unfriendly", "friendly"),
        ("impossible", "possible"),
        ("desert", "dessert"),
        ("feather", "father"),
        ("laughter", "daughter"),
        ("weather", "whether"),
        ("seventeenth", "seventieth"),
    ],
)
def test_a_word_one_letter_or_a_prefix_from_another_is_another_word(one: str, other: str) -> None:
    assert not same_word(one, other)
    assert same_word("temprature", "temperature")  # a slip in a long word is forgiven
