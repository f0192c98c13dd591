"""The child asks; the robot hears it through Silero VAD and Whisper and picks the rule.
Real models on synthesized speech (two voices, two speeds, noise), never mocks."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from engine.dialogs.model import Dialog, FollowUp
from engine.media.audio import Audio
from engine.speech.hearing import hear
from engine.speech.recognizer import Recognizer
from engine.speech.vad import SileroVad

QUESTIONS = {
    "name": "what is your name",
    "color": "what is your favorite color",
    "temperature": "what is the temperature",
    "how_are_you": "how are you doing",
    "pets": "do you like animals",
}
WAYS = [
    ("joe", 0.9, None),
    ("joe", 1.2, None),
    ("espeak", 0.9, None),
    ("espeak", 1.2, None),
    ("joe", 1.0, 10.0),
]


@pytest.mark.parametrize(("voice", "speed", "snr_db"), WAYS)
@pytest.mark.parametrize("rule", sorted(QUESTIONS))
def test_every_rule_is_understood_in_each_voice_speed_and_in_noise(
    rule: str,
    voice: str,
    speed: float,
    snr_db: float | None,
    spoken: Callable[..., Audio],
    vad: SileroVad,
    recognizer: Recognizer,
    default_dialog: Dialog,
) -> None:
    hearing = hear(spoken(QUESTIONS[rule], voice, speed, snr_db), vad, recognizer, default_dialog)
    assert hearing.verdict is not None and hearing.verdict.match is not None, hearing
    assert hearing.verdict.match.rule.id == rule


@pytest.mark.parametrize(
    "sentence",
    [
        "do you like cake",
        "how old are you",
        "what is your favorite food",
        "can you dance for me",
        "where do you live",
    ],
)
def test_questions_outside_the_dialog_are_never_answered(
    sentence: str,
    spoken: Callable[..., Audio],
    vad: SileroVad,
    recognizer: Recognizer,
    default_dialog: Dialog,
) -> None:
    hearing = hear(spoken(sentence), vad, recognizer, default_dialog)
    assert hearing.heard is not None
    assert hearing.verdict is not None and hearing.verdict.match is None, hearing
    # the fallback, or, where it sounds like a rule that says how, the question that
    # confirms it ("do you like cake": "Did you ask whether I like animals?")
    if hearing.asks is None:
        assert hearing.answer == "Sorry, I did not understand."
    else:
        assert hearing.answer == hearing.asks.confirm.source


def test_the_answer_to_the_robot_s_question_is_heard_as_the_follow_up(
    spoken: Callable[..., Audio],
    vad: SileroVad,
    recognizer: Recognizer,
    default_dialog: Dialog,
    pets_answers: FollowUp,
) -> None:
    hearing = hear(spoken("yes, I have a dog"), vad, recognizer, default_dialog, pets_answers)
    assert hearing.verdict is not None and hearing.verdict.match is not None
    assert hearing.verdict.match.rule.id == "has_pet"
    hearing = hear(spoken("no"), vad, recognizer, default_dialog, pets_answers)
    assert hearing.verdict is not None and hearing.verdict.match is not None
    assert hearing.verdict.match.rule.id == "no_pet"


def test_noise_alone_is_not_heard_as_anything(
    vad: SileroVad, recognizer: Recognizer, default_dialog: Dialog
) -> None:
    from engine.media.audio import noise

    for level in (-40.0, -25.0):
        hearing = hear(noise(5.0, level, seed=3), vad, recognizer, default_dialog)
        assert hearing.heard is None
