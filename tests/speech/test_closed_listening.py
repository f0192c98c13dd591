"""Issue 24: when Moonshine's words hold none of the dialogs' phrases, it hears the audio
again allowed to write only those phrases, and the phrase is kept only when the audio
bears it out.

The search's stories use a scripted decoder (a fake: it gives each next piece the
log-probability its script says), so they are exact; the last stories hear real speech
with the real model."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np
import pytest

from engine.dialogs.model import Dialog, FollowUp
from engine.media.audio import Audio
from engine.speech.hearing import hear
from engine.speech.moonshine import MoonshineRecognizer
from engine.speech.phrase_search import (
    CLOSE_ENOUGH_NATS,
    Found,
    PhraseGrammar,
    bears_out,
    closest_phrase,
    closest_phrases,
    left_out,
    sure_of,
)
from engine.speech.recognizer import Abandon, Recognizer, Transcript, Word
from engine.speech.recognizers import SecondOpinion
from engine.speech.vad import SileroVad
from engine.speech.voices import Voice

END = 2
PIECES = ["", "", "", " Do", " you", " like", " dog", " it", "?", " dogs", " How", " are"]
PIECES += [" kitten"]
IMPOSSIBLE = -np.inf


class ScriptedDecoder:
    """Gives the pieces its script names for the text so far their log-probabilities
    (the end: ``"</s>"``); every other piece is impossible."""

    def __init__(self, script: dict[str, dict[str, float]]) -> None:
        self.script = script
        self.texts: list[str] = []
        self.steps = 0

    def first(self) -> np.ndarray:
        self.texts = [""]
        return self._rows()

    def then(self, parents: np.ndarray, tokens: np.ndarray) -> np.ndarray:
        self.steps += 1
        self.texts = [self.texts[p] + PIECES[t] for p, t in zip(parents, tokens, strict=True)]
        return self._rows()

    def _rows(self) -> np.ndarray:
        rows = np.full((len(self.texts), len(PIECES)), IMPOSSIBLE)
        for row, text in enumerate(self.texts):
            for piece, log_prob in self.script.get(text, {}).items():
                rows[row, END if piece == "</s>" else PIECES.index(piece)] = log_prob
        return rows


GRAMMAR = PhraseGrammar(["do you like dog", "do you like kitten", "how are you"])


def search(script: dict[str, dict[str, float]]) -> Found | None:
    return closest_phrase(ScriptedDecoder(script), GRAMMAR, PIECES, end_token=END, max_tokens=8)


def test_a_word_heard_wrong_is_written_as_the_phrase_the_model_finds_likeliest() -> None:
    # Free, the model writes "Do you like it?"; "dogs" is its second choice, "kitten" far off
    script = {
        "": {" Do": -0.1},
        " Do": {" you": -0.1},
        " Do you": {" like": -0.1},
        " Do you like": {" it": -0.5, " dogs": -1.5, " kitten": -6.0},
        " Do you like dogs": {"?": -0.2, "</s>": -1.0},
        " Do you like dogs?": {"</s>": -0.1},
        " Do you like kitten": {"</s>": -0.1},
    }
    found = search(script)
    assert found is not None
    assert found.text == "do you like dogs"  # a phrase's word in the plural, "?" aside
    assert found.log_prob == pytest.approx(-0.1 * 3 - 1.5 - 0.2 - 0.1)


def test_a_search_writes_nothing_it_cannot_finish_as_a_phrase() -> None:
    # "Do you" could become a phrase, but the model never ends it as one
    script = {"": {" Do": -0.1}, " Do": {" you": -0.1}, " Do you": {"</s>": -0.1}}
    assert search(script) is None


def test_the_search_stops_once_no_text_can_beat_the_phrase_it_has() -> None:
    script = {
        "": {" How": -0.1, " Do": -9.0},
        " How": {" are": -0.1},
        " How are": {" you": -0.1},
        " How are you": {"</s>": -0.1},
        " Do": {" you": -0.1},
    }
    decoder = ScriptedDecoder(script)
    found = closest_phrase(decoder, GRAMMAR, PIECES, end_token=END, max_tokens=8)
    assert found is not None and found.text == "how are you"
    assert found.log_prob == pytest.approx(-0.4)
    assert decoder.steps == 3  # the "Do ..." text (-9) was never carried further


def test_a_search_gives_up_on_texts_less_likely_than_a_phrase_can_be_of_use() -> None:
    # the free transcript was likely (-1 nat): a phrase 5 nats below it is not borne out
    script = {
        "": {" Do": -0.1},
        " Do": {" you": -3.0},
        " Do you": {" like": -3.0},
        " Do you like": {" dog": -0.1},
        " Do you like dog": {"</s>": -0.1},
    }
    decoder = ScriptedDecoder(script)
    floor = -1.0 - CLOSE_ENOUGH_NATS
    found = closest_phrase(decoder, GRAMMAR, PIECES, end_token=END, max_tokens=8, at_least=floor)
    assert found is None
    assert decoder.steps == 2  # "Do you like" (-6.1) fell below the floor: not decoded on
    unbounded = search(script)  # without a floor: found, and only then judged
    assert unbounded is not None and unbounded.log_prob == pytest.approx(-6.3)


def test_a_search_for_the_runner_up_looks_only_near_the_best() -> None:
    script = {
        "": {" How": -0.1, " Do": -3.0},
        " How": {" are": -0.1},
        " How are": {" you": -0.1},
        " How are you": {"</s>": -0.1},
        " Do": {" you": -3.0},
        " Do you": {" like": -3.0},
        " Do you like": {" dog": -0.1},
        " Do you like dog": {"</s>": -0.1},
    }
    everything = closest_phrases(
        ScriptedDecoder(script), GRAMMAR, PIECES, end_token=END, max_tokens=8, keep=2
    )
    assert [f.text for f in everything] == ["how are you", "do you like dog"]
    decoder = ScriptedDecoder(script)
    near = closest_phrases(decoder, GRAMMAR, PIECES, end_token=END, max_tokens=8, keep=2, near=5)
    assert [f.text for f in near] == ["how are you"]  # "Do you" (-6) is 5.6 below the best
    assert decoder.steps == 3


def test_a_text_on_the_way_to_short_phrases_only_gives_up_sooner() -> None:
    # a phrase may be 2 nats a word below -1: "how are you" down to -7, "do you like dog"
    # down to -9; both texts are at -8 after their second word
    script = {
        "": {" How": -0.1, " Do": -0.1},
        " How": {" are": -7.9},
        " How are": {" you": -0.1},
        " How are you": {"</s>": -0.1},
        " Do": {" you": -7.9},
        " Do you": {" like": -0.1},
        " Do you like": {" dog": -0.1},
        " Do you like dog": {"</s>": -0.1},
    }
    found = closest_phrases(
        ScriptedDecoder(script),
        GRAMMAR,
        PIECES,
        end_token=END,
        max_tokens=8,
        at_least=-9.0,
        keep=2,
        floor_for=lambda words: -1.0 - 2.0 * words,
    )
    assert [f.text for f in found] == ["do you like dog"]


def words_heard(text: str, probability: float = 0.9) -> list[tuple[str, float]]:
    return [(word, probability) for word in text.split()]


def test_a_phrase_nearly_as_likely_as_the_free_transcript_with_a_word_misheard_is_kept() -> None:
    found = Found("how hot is it", -4.0)
    assert bears_out(found, -1.5, words_heard("How art is it?"), GRAMMAR)


def test_a_phrase_much_less_likely_than_the_free_transcript_is_not() -> None:
    found = Found("how are you", -1.0 - CLOSE_ENOUGH_NATS - 0.1)
    assert not bears_out(found, -1.0, words_heard("How old are you?", 0.3), GRAMMAR)


def test_a_word_clearly_heard_that_the_phrase_leaves_out_means_another_question() -> None:
    found = Found("how are you", -2.0)
    assert not bears_out(found, -1.0, words_heard("How tall are you?"), GRAMMAR)
    # heard unsure, the same word may be noise
    assert bears_out(found, -1.0, words_heard("How tall are you?", 0.4), GRAMMAR)


def test_a_word_of_another_phrase_heard_more_likely_than_not_is_never_overruled() -> None:
    grammar = PhraseGrammar(["what is your name", "what is your favorite color"])
    heard = [("What", 0.7), ("in", 0.4), ("your", 0.99), ("amber", 0.47), ("color?", 0.58)]
    assert not bears_out(Found("what is your name", -4.0), -1.0, heard, grammar)


def test_words_left_out_are_those_the_phrase_has_nothing_in_place_of() -> None:
    heard = words_heard("how tall are you")
    assert left_out(heard, ["how", "are", "you"]) == [("tall", 0.9)]
    assert left_out(words_heard("my word"), ["my", "bird"]) == []  # in place of "bird"
    assert left_out(words_heard("yes yes"), ["yes"]) == []  # said twice


def test_a_phrase_is_sure_when_likely_word_by_word_long_enough_and_something_was_written() -> None:
    heard = words_heard("How hard is it?")
    assert sure_of(Found("how hot is it", -4.0), heard)  # -0.8 a word and its end
    assert not sure_of(Found("how hot is it", -12.0), heard)  # a long mumble forced in
    assert not sure_of(Found("yes", -0.5), words_heard("Mm."))  # one word: never sure
    assert not sure_of(Found("how hot is it", -1.0), [])  # Moonshine wrote nothing


def test_a_phrase_that_only_adds_a_meaning_word_to_what_was_written_is_not_sure() -> None:
    trailing_off = words_heard("What is your")
    assert not sure_of(Found("what is your name", -2.0), trailing_off)
    assert sure_of(Found("do you like dogs", -2.0), words_heard("you like dogs"))  # "do"
    assert sure_of(Found("what is your name", -2.0), words_heard("What is your aim?"))


class SaysRecognizer:
    """Says what it is told to, finds the phrases it is told it would find, and counts
    what it heard."""

    name = "says"

    def __init__(self, transcript: Transcript, *, would_find: Iterable[str] = ()) -> None:
        self.transcript = transcript
        self.would_find = set(would_find)
        self.heard = 0
        self.asked: list[list[str]] = []

    def listen_for(self, phrases: Iterable[str]) -> None:
        pass

    def transcribe(self, audio: Audio, *, abandon: Abandon | None = None) -> Transcript:
        self.heard += 1
        return self.transcript

    def finds(self, audio: Audio, phrases: Iterable[str]) -> bool:
        self.asked.append(sorted(phrases))
        return bool(self.would_find & set(self.asked[-1]))


PETS = ["yes", "yeah", "yeah i have a puppy", "i have a puppy", "hello", "no"]


def test_whisper_hears_again_only_a_phrase_closed_listening_is_not_sure_of() -> None:
    fast = SaysRecognizer(Transcript("how hot is it"))
    careful = SaysRecognizer(Transcript("Yes."))
    both = SecondOpinion(fast, careful)
    both.listen_for(PETS)
    assert both.transcribe(Audio.silence(1.0)).text == "how hot is it"
    fast.transcript = Transcript("", unconfirmed="yes")  # a short "yes", or "mm"?
    assert both.transcribe(Audio.silence(1.0)).text == "Yes."
    assert (fast.heard, careful.heard, both.second_opinions) == (2, 1, 1)


def test_whisper_s_transcript_counts_where_it_says_the_phrase_moonshine_was_unsure_of() -> None:
    fast = SaysRecognizer(Transcript("", unconfirmed="yeah"))
    both = SecondOpinion(fast, SaysRecognizer(Transcript("Yeah, I have a puppy?")))
    both.listen_for(PETS)
    assert both.transcribe(Audio.silence(1.0)).text == "Yeah, I have a puppy?"


def test_whisper_writing_another_phrase_counts_only_where_moonshine_finds_it_too() -> None:
    fast = SaysRecognizer(Transcript("", unconfirmed="yes"), would_find=["yeah"])
    both = SecondOpinion(fast, SaysRecognizer(Transcript("Yeah?")))
    both.listen_for(PETS)
    assert both.transcribe(Audio.silence(1.0)).text == "Yeah?"
    assert fast.asked == [["yeah"]]


def test_three_words_both_recognizers_wrote_are_heard_though_whisper_doubted_them() -> None:
    # espeak's "who are you": Moonshine borne out but not sure; prompted Whisper wrote
    # "Who are you?" (its first word at 0.02) and, unprompted, "Thank you."
    doubted = Transcript("", (Word("Who", 0.02), Word("are", 0.68), Word("you?", 0.98)))
    fast = SaysRecognizer(Transcript("", unconfirmed="who are you"))
    both = SecondOpinion(fast, SaysRecognizer(doubted))
    both.listen_for(["who are you", "hi"])
    assert both.transcribe(Audio.silence(1.0)).text == "Who are you?"
    # a shorter phrase so written is no agreement: a sound is forced into "hi" by both
    fast.transcript = Transcript("", unconfirmed="hi")
    both.careful = SaysRecognizer(Transcript("", (Word("Hi?", 0.03),)))
    assert both.transcribe(Audio.silence(1.0)).text == ""


def test_a_sound_the_two_recognizers_hear_as_different_phrases_is_heard_as_nothing() -> None:
    # "huh": Moonshine finds "yeah" nearest, Whisper prompted with the phrases "Hello?"
    fast = SaysRecognizer(Transcript("Huh?", unconfirmed="yeah"))
    careful = SaysRecognizer(Transcript("Hello?"))
    both = SecondOpinion(fast, careful)
    both.listen_for(PETS)
    assert both.transcribe(Audio.silence(1.0)).text == ""
    assert fast.asked == [["hello"]]
    careful.transcript = Transcript("Mm.")  # no phrase at all: nothing to ask
    assert both.transcribe(Audio.silence(1.0)).text == ""
    assert fast.asked == [["hello"]]


def test_where_moonshine_writes_nothing_only_phrases_of_words_are_looked_for() -> None:
    grammar = PhraseGrammar(["Hello!", "yes", "how are you", "do you like dog"])
    assert grammar.sentences.spellings == ["do you like dog", "how are you"]


def test_the_grammar_reads_phrases_as_spelled_whatever_the_case_and_marks() -> None:
    assert GRAMMAR.allows(" Do you lik")
    assert GRAMMAR.complete(" How are you?")
    assert not GRAMMAR.allows(" How are you doing")
    assert not GRAMMAR.complete(" Do you like")


# -- the real model --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("said", "voice", "speed", "snr_db", "rule"),
    [
        ("how hot is it", "hibari", 1.0, None, "temperature"),  # freely: "How hard is it?"
        ("hi there", "joe", 0.85, None, "greeting"),  # freely: "Hide there,"
        # the fallback voice, which Moonshine writes nothing for: the phrase is weighed
        # against the words it would write
        ("yep i have a puppy", "espeak", 1.0, None, "has_pet"),
        ("yeah i have a puppy", "espeak", 1.0, None, "has_pet"),
        # "L meet your name": a beam of four texts lost "tell" to likelier first pieces
        ("tell me your name", "espeak", 0.9, 10.0, "name"),
    ],
)
def test_a_phrase_moonshine_writes_wrong_is_heard_right_through_the_phrases(
    said: str,
    voice: str,
    speed: float,
    snr_db: float | None,
    rule: str,
    spoken: Callable[..., Audio],
    vad: SileroVad,
    recognizer: Recognizer,
    default_dialog: Dialog,
    pets_answers: FollowUp,
) -> None:
    context = pets_answers if rule == "has_pet" else None
    hearing = hear(spoken(said, voice, speed, snr_db), vad, recognizer, default_dialog, context)
    assert hearing.verdict is not None and hearing.verdict.match is not None, hearing
    assert hearing.verdict.match.rule.id == rule


def test_moonshine_gives_up_a_recognition_at_the_step_it_is_told_to(
    spoken: Callable[..., Audio], default_dialog: Dialog
) -> None:
    moonshine = MoonshineRecognizer()
    moonshine.listen_for(default_dialog.phrases)
    audio = spoken("what is your name")
    asked: list[bool] = []

    def after_three_steps() -> bool:
        asked.append(len(asked) >= 3)
        return asked[-1]

    assert moonshine.transcribe(audio, abandon=after_three_steps).text == ""
    assert asked == [False, False, False, True]  # no step decoded after it was told
    assert moonshine.transcribe(audio).text == "What is your name?"  # the next is whole


@pytest.mark.parametrize("sentence", ["how old are you", "are you a robot", "how tall are you"])
def test_a_question_no_rule_means_is_not_taken_for_the_phrase_it_sounds_like(
    sentence: str,
    spoken: Callable[..., Audio],
    vad: SileroVad,
    recognizer: Recognizer,
    default_dialog: Dialog,
) -> None:
    hearing = hear(spoken(sentence, "joe", 0.85), vad, recognizer, default_dialog)
    assert hearing.verdict is not None and hearing.verdict.match is None, hearing


@pytest.mark.parametrize("sound", ["mmm", "oh", "ha ha ha"])
def test_a_sound_after_the_robot_s_question_is_not_taken_for_yes_or_no(
    sound: str,
    spoken: Callable[..., Audio],
    vad: SileroVad,
    recognizer: Recognizer,
    default_dialog: Dialog,
    pets_answers: FollowUp,
) -> None:
    hearing = hear(spoken(sound, "hibari"), vad, recognizer, default_dialog, pets_answers)
    assert hearing.verdict is None or hearing.verdict.match is None, hearing


def test_a_huh_is_not_taken_for_a_greeting(
    voices: dict[str, Voice], vad: SileroVad, recognizer: Recognizer, default_dialog: Dialog
) -> None:
    # a breaker's recording: Moonshine wrote "Huh?" and found "yeah" nearest among the
    # phrases (not sure of it); prompted Whisper wrote "Hello?"
    huh = voices["hibari"].synthesize("huh").resampled(16000)
    audio = Audio.silence(0.5, 16000).then(huh).then(Audio.silence(1.0, 16000))
    hearing = hear(audio, vad, recognizer, default_dialog)
    assert hearing.verdict is None or hearing.verdict.match is None, hearing


def test_a_sentence_played_backwards_is_not_taken_for_a_phrase(
    spoken: Callable[..., Audio], vad: SileroVad, recognizer: Recognizer, default_dialog: Dialog
) -> None:
    forwards = spoken("hello my name is sam and i am seven years old", "hibari")
    backwards = Audio(forwards.samples[::-1].copy(), forwards.rate_hz)
    hearing = hear(backwards, vad, recognizer, default_dialog)
    assert hearing.verdict is None or hearing.verdict.match is None, hearing
