"""Hearing children: which phrase a child said, where a recognizer trained on adults misses.

Moonshine was trained on adults. A six-year-old's "Can we play a game?" comes out as "Can
you play again?", "I have a puppy" as "I have a poppy": words a child never said, in which
no phrase of the dialog stands, so the robot said "sorry" to most young children. Closed
listening (:mod:`engine.speech.phrase_search`) finds the phrase, but the adult rule that
keeps it (:func:`~engine.speech.phrase_search.bears_out`: the phrase within 5 nats of the
free transcript) was set on adults' voices, and a child's phrase is further from what an
adult-trained model writes for it: a few nats a word.

A child's phrase is kept (:func:`a_child_said`) when all of these hold:

- it is at most :data:`NATS_PER_WORD` a word (and at least 5 nats) less likely than the
  free transcript: the longer the phrase, the more its words may sound unlike an adult's;
- the next likeliest phrase stands :data:`MARGIN_NATS` lower: a phrase heard from two
  alike ("I like dogs", "I like frogs") is not told apart;
- what Moonshine wrote freely is :data:`ALIKE` like it (:func:`~engine.dialogs.words.alike`;
  :data:`ALIKE_ALONE` where the dialog has no other phrase near enough to weigh it against):
  "can you play again" is like "can we play a game"; "I want my mommy" is not like "my
  favorite color is blue", however likely the search found it;
- nothing it wrote clearly (:data:`~engine.speech.phrase_search.CLEARLY_HEARD`) is left out
  of the phrase, as for adults;
- it wrote no person or question word that the phrase lacks with probability
  :data:`OTHERWISE_HEARD` or more, and no negation at all
  (:func:`~engine.dialogs.words.says_otherwise`: "what is *my* name" is not "what is your
  name", "is it *not* cold" not "is it cold");
- Moonshine wrote some words: where it wrote none, the adult rule and the second opinion
  decide.

On the children's clips (bench/bench_speech.py, speakers the rule was never set on) it
answers most six-to-eight-year-olds where the adult rule answered a third, and tells no one
a phrase they did not say; a profile turns it on with ``hearing: children``
(:mod:`engine.speech.settings`).
"""

from __future__ import annotations

from collections.abc import Sequence

from engine.dialogs.words import NEGATIONS, alike, says_otherwise, words
from engine.speech.phrase_search import CLEARLY_HEARD, CLOSE_ENOUGH_NATS, Found, left_out

NATS_PER_WORD = 2.0
"""A child's phrase may be this much less likely per word (natural log) than the free
transcript. Set on 400 clips of 20 children: 1.5 answered 8 fewer of them, 2.5 only 4
more."""
MARGIN_NATS = 2.0
"""The phrase found must be this much likelier (natural log) than the next phrase found:
e^2, about 7 times."""
ALIKE = 0.45
"""What Moonshine wrote must be this alike the phrase (0..1, :func:`alike`)."""
ALIKE_ALONE = 0.6
"""As :data:`ALIKE`, where no other phrase was found to weigh the phrase against."""
OTHERWISE_HEARD = 0.75
"""A person or question word written at least this likely that the phrase lacks refuses it
(:func:`~engine.dialogs.words.says_otherwise`; a negation, however unlikely): at 0.5, two
of the four children of examples/children-speech lost their sentence ("*I* was late" for
"he was late", "*where* you'll be" for "will you be")."""
BEAM = 8
"""Texts the children's search carries on at each step: half the adults' (its floor is
lower, so more texts stay above it; 16 took 0.4 s a search on 2 cores, too slow to answer
within half a second, and answered 1 more child in 40)."""
NEAR_NATS = 10.0
"""Another phrase this much less likely than the best (natural log) is near enough to weigh
the best against (:data:`ALIKE`); the search looks no further below the best."""


def search_floor(free_log_prob: float, most_words: int) -> float:
    """The least likely a phrase of ``most_words`` words may be and still be kept (natural
    log), where the free transcript is ``free_log_prob``: what the search need not look
    below."""
    return free_log_prob - max(CLOSE_ENOUGH_NATS, NATS_PER_WORD * most_words)


def a_child_said(
    found: Sequence[Found], free_log_prob: float, heard: Sequence[tuple[str, float]]
) -> Found | None:
    """The phrase a child said, of ``found`` (the likeliest phrases closed listening found,
    likeliest first), or None where none is borne out (see the module's docstring).
    ``free_log_prob``: the free transcript's log-probability (natural log); ``heard``: each
    word Moonshine wrote and its probability."""
    if not found or not heard:
        return None
    best = found[0]
    phrase = words(best.text)
    if best.log_prob < search_floor(free_log_prob, len(phrase)):
        return None
    if len(found) > 1 and best.log_prob - found[1].log_prob < MARGIN_NATS:
        return None
    written = " ".join(text for text, _ in heard)
    if alike(best.text, written) < (ALIKE if len(found) > 1 else ALIKE_ALONE):
        return None
    said = [(word, probability) for text, probability in heard for word in words(text)]
    if any(probability >= CLEARLY_HEARD for _, probability in left_out(said, phrase)):
        return None
    sure = [word for word, p in said if p >= OTHERWISE_HEARD or word in NEGATIONS]
    if says_otherwise(sure, phrase):
        return None  # "what is my name" is never "what is your name", however alike
    return best
