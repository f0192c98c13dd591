"""Issue 38: the robot understands children.

A robot whose profile says ``hearing: children`` waits longer when a child pauses within a
sentence, keeps a child's breathy first word, and keeps a phrase as children say it (far
from what a model trained on adults writes, but like it, and standing out from the other
phrases). The rule's stories are exact (phrases found and their log-probabilities given);
the last ones hear real children (examples/children-speech, speakers the rule was never
set on)."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.dialogs.words import alike, normalize
from engine.media.audio import Audio
from engine.speech.children import ALIKE_ALONE, MARGIN_NATS, NATS_PER_WORD, a_child_said
from engine.speech.phrase_search import Found
from engine.speech.vad import SileroVad, speech_detector
from engine.speech.voices import Voice

ROOT = Path(__file__).resolve().parents[2]


def written(text: str, probability: float = 0.6) -> list[tuple[str, float]]:
    return [(word, probability) for word in text.split()]


def test_a_child_s_phrase_further_from_the_free_transcript_than_an_adult_s_is_kept() -> None:
    # "can we play a game", said by a six-year-old, written "Can you play again?"
    heard = written("Can you play again?")
    found = [Found("can we play a game", -9.0), Found("can we play again", -13.0)]
    assert a_child_said(found, -1.0, heard) == found[0]  # 8 nats below: 1.6 a word


def test_the_longer_the_phrase_the_further_it_may_be() -> None:
    heard = written("I have a poppy")
    gap = NATS_PER_WORD * 4
    assert a_child_said([Found("i have a puppy", -1.0 - gap + 0.1)], -1.0, heard)
    assert a_child_said([Found("i have a puppy", -1.0 - gap - 0.1)], -1.0, heard) is None


def test_a_phrase_that_does_not_stand_out_from_the_next_is_not_told_apart() -> None:
    heard = written("I like frocks")
    close = [Found("i like frogs", -4.0), Found("i like dogs", -4.0 - MARGIN_NATS + 0.5)]
    assert a_child_said(close, -2.0, heard) is None
    apart = [Found("i like frogs", -4.0), Found("i like dogs", -4.0 - MARGIN_NATS - 0.5)]
    assert a_child_said(apart, -2.0, heard) == apart[0]


def test_a_likely_phrase_unlike_what_was_written_is_not_what_the_child_said() -> None:
    heard = written("I want my mommy")
    found = [Found("my favorite color is blue", -6.0), Found("my sister is two", -12.0)]
    assert alike(found[0].text, "I want my mommy") < 0.45
    assert a_child_said(found, -2.0, heard) is None


def test_a_phrase_with_nothing_to_weigh_it_against_must_be_more_alike() -> None:
    heard = written("What did you want to say me about?")
    alone = Found("what did you want to see me about", -2.0)
    assert alike(alone.text, "What did you want to say me about?") >= ALIKE_ALONE
    assert a_child_said([alone], -1.0, heard) == alone
    unlike = Found("what do you want", -2.0)
    assert a_child_said([unlike], -1.0, written("What a wonderful day")) is None


def test_a_word_written_clearly_that_the_phrase_leaves_out_means_something_else() -> None:
    found = [Found("i like dogs", -3.0), Found("i like frogs", -9.0)]
    assert a_child_said(found, -1.0, written("I like dogs and cats", 0.9)) is None
    # written unsure, the same word may be the child's own sound
    assert a_child_said(found, -1.0, written("I like dogs and cats", 0.4)) == found[0]


def test_where_nothing_was_written_the_child_rule_leaves_it_to_the_others() -> None:
    assert a_child_said([Found("yes", -1.0)], -1.0, []) is None
    assert a_child_said([], -1.0, written("hello")) is None


@pytest.mark.parametrize(
    ("written_by_a_recognizer", "as_a_phrase"),
    [
        ("Good-bye.", "goodbye"),
        ("Twenty-one!", "twenty one"),
        ("I'm 6.", "i am six"),
        ("My 6th birthday", "my sixth birthday"),
        ("It's the 21st", "it is the twenty first"),
        ("5-29-0.", "five twenty nine zero"),
        ("Call 2287", "call two two eight seven"),
        ("The 3rd and 12th", "the third and twelfth"),
    ],
)
def test_what_a_recognizer_writes_its_own_way_is_read_as_a_person_writes_a_phrase(
    written_by_a_recognizer: str, as_a_phrase: str
) -> None:
    assert normalize(written_by_a_recognizer) == as_a_phrase


def paused(voice: Voice, first: str, then: str, pause_s: float) -> Audio:
    before, gap, after = Audio.silence(0.3), Audio.silence(pause_s), Audio.silence(1.2)
    return before.then(voice.synthesize(first)).then(gap).then(voice.synthesize(then)).then(after)


def test_a_child_s_pause_within_a_sentence_does_not_cut_it_in_two(
    vad: SileroVad, voices: dict[str, Voice]
) -> None:
    audio = paused(voices["joe"], "Mike", "likes the white one", 0.6)
    adults = speech_detector(vad)
    vad.reset()
    cut = adults.feed(audio.samples)
    children = speech_detector(vad, children=True)
    vad.reset()
    whole = children.feed(audio.samples)
    assert len(cut) == 2
    assert len(whole) == 1
