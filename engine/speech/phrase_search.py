"""Closed listening: which of the dialogs' phrases the audio holds, when free hearing missed.

Moonshine writes what it hears, and a robotic voice in noise comes out as "My word" for
"my bird" or "How art is it?" for "how hot is it". When what it wrote holds none of the
dialogs' phrases (:meth:`PhraseGrammar.holds_a_phrase`), the same model hears the same
audio again, this time allowed to write only the phrases the robot listens for: a beam
search whose every token must keep the text (case, punctuation and spaces aside) on the
way to one of them (:func:`closest_phrase`). It costs a few decoder steps on the encoder
output already computed, about a tenth of a second, where Whisper's second opinion took
0.8 s.

Closed listening always finds *some* phrase, so the phrase is kept only when the audio
bears it out (:func:`bears_out`):

- the model's own log-probability of the phrase is within :data:`CLOSE_ENOUGH_NATS` of
  the log-probability of what it wrote freely (the phrase is nearly as likely as its own
  best guess);
- nothing the model heard clearly is left out: no meaning word it wrote with probability
  :data:`CLEARLY_HEARD` or more that the phrase lacks ("how *tall* are you" is not "how
  are you"), and no word of another of the dialogs' phrases that it wrote more likely than
  not (:data:`KEYWORD_HEARD`) ("what in your amber with *color*" is not "what is your name").

Otherwise the utterance is heard as what Moonshine wrote, which holds no phrase: the
robot says it did not understand rather than answer a guess. A phrase borne out but not
*sure* (:func:`sure_of`: a short sound forced into "yes", a long mumble into a short
phrase) is left for a careful recognizer to hear again
(:class:`~engine.speech.recognizers.SecondOpinion`). bench/bench_speech.py
measures the thresholds' effect on 662 clips (right, wrong, stray sentences accepted).
"""

from __future__ import annotations

import functools
import itertools
import math
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from engine.dialogs.words import is_function_word, same_word, words

__all__ = [
    "CLEARLY_HEARD",
    "CLOSE_ENOUGH_NATS",
    "KEYWORD_HEARD",
    "Decoding",
    "Found",
    "PhraseGrammar",
    "bears_out",
    "closest_phrase",
    "closest_phrases",
    "left_out",
    "sure_of",
]

CLOSE_ENOUGH_NATS = 5.0
"""A phrase is heard when the model finds it at most this much less likely (natural log)
than its own free transcript: e^-5, about 1 in 150. Measured on bench_speech's clips: 4
loses 9 right answers, 6 lets "how hot is it" (espeak, 10 dB of noise) through as "how are
you"."""
CLEARLY_HEARD = 0.75
"""A meaning word written with at least this probability was said: a phrase without it is
not what was said."""
KEYWORD_HEARD = 0.5
"""A word of one of the dialogs' phrases written more likely than not was said: a phrase
without it is not what was said."""
SURE_PER_WORD = -2.0
"""A phrase borne out is *sure* when the model gives it at least this log-probability per
word (and its end) on average, it has two words or more, and Moonshine wrote some words
of its own: otherwise a careful recognizer hears the utterance again. A short sound
("mm", "oh", a laugh) forced into "yes", "no" or "hi", or a long mumble into a short
phrase, is borne out relative to a doubtful transcript but never sure."""
BEAM = 16
"""Texts kept at each step of the search. Four lost phrases whose first piece is not among
the likeliest ("tell me your name" to " L", " Well", " W", " What"; "who are you" to
" W", " What", " Where"): on bench_speech's clips 16 found 6 more right answers than 4, and
no wrong one, for about 50 ms more at the 90th percentile of a search (130 ms)."""
TOP_TOKENS = 50
"""Of each text's next tokens, the likeliest this many are tried against the phrases."""

MAX_PLURALS = 8
"""Words of a phrase that may be said in the plural (2**8 ways at most)."""

_NOT_SPELLED = re.compile(r"[^a-z0-9' ]")


def spelled(text: str) -> str:
    """``text`` as the phrases are compared with it: lower case, letters, digits and single
    spaces (a trailing space kept: a word may follow)."""
    plain = _NOT_SPELLED.sub(" ", text.lower()).replace("'", "")
    return re.sub(" +", " ", plain).lstrip()


class PhraseGrammar:
    """The phrases the robot listens for, as texts a search may write."""

    def __init__(self, phrases: Iterable[str]) -> None:
        self._written = {spelled(phrase).strip(): phrase for phrase in phrases}
        listened = set(self._written) - {""}
        self.spellings = sorted(listened)
        """Each phrase as :func:`spelled`."""
        self.phrases = [words(text) for text in self.spellings]
        self.texts = {said for text in listened for said in with_plurals(text)}
        self.longest = max((len(text) for text in self.texts), default=0)
        """Characters of the longest text."""
        self._prefixes: dict[str, int] = {}  # each text's beginnings: its most words
        for text in self.texts:
            count = len(text.split())
            for end in range(len(text) + 1):
                begun = text[:end]
                self._prefixes[begun] = max(count, self._prefixes.get(begun, 0))
        self.keywords = {
            word for phrase in self.phrases for word in phrase if not is_function_word(word)
        }
        begins = {phrase[:end] for phrase in self.phrases for end in range(1, len(phrase))}
        self._whole_turns = set(self.phrases) - begins

    def __bool__(self) -> bool:
        return bool(self.texts)

    @functools.cached_property
    def sentences(self) -> PhraseGrammar:
        """The phrases of two words or more."""
        return PhraseGrammar(text for text in self.spellings if len(text.split()) >= 2)

    def allows(self, text: str) -> bool:
        """Whether ``text`` is on the way to a phrase, or is one (trailing marks aside)."""
        plain = spelled(text)
        return plain in self._prefixes or plain.rstrip() in self.texts

    def complete(self, text: str) -> bool:
        return spelled(text).rstrip() in self.texts

    def most_words(self, text: str) -> int:
        """The most words of a phrase ``text`` is on the way to (0: none)."""
        plain = spelled(text)
        return self._prefixes.get(plain, 0) or len(plain.split()) * self.complete(text)

    def written(self, spelling: str) -> str:
        """A phrase as the dialog writes it, from its spelling ("but its not" is "but it's
        not": the matcher reads "it's" as "it is"); a plural made here as it is."""
        return self._written.get(spelling, spelling)

    def is_a_whole_turn(self, text: str) -> bool:
        """Whether ``text`` says one of the phrases and nothing more (case, punctuation,
        contractions and plurals aside: "What's your name?", "Do you like puppies?"), and
        no other phrase goes on from it: "i do" is not a whole turn beside "i do not", nor
        "yes" beside "yes i have a dog", for a person who pauses after it may go on."""
        return words(text) in self._whole_turns

    def holds_a_phrase(self, text: str) -> bool:
        """Whether ``text`` holds every meaning word of one of the phrases, or all the words
        of a phrase of function words only ("how are you"), and no meaning word that none
        of them has (a word misheard beside the phrase's: "what is your favorite
        mid-colour")."""
        heard = words(text)
        if any(word not in self.keywords and not is_function_word(word) for word in heard):
            return False
        for phrase in self.phrases:
            meaning = [word for word in phrase if not is_function_word(word)]
            if not meaning:
                if tuple(heard) == phrase:
                    return True
            elif all(any(same_word(h, word) for h in heard) for word in meaning):
                return True
        return False


def with_plurals(text: str) -> list[str]:
    """``text`` and the ways of saying it with its meaning words in the plural ("do you like
    dog": "do you like dogs"), as the matcher hears them; at most :data:`MAX_PLURALS` of
    its words (words ending in "s" stay as they are)."""
    choices: list[list[str]] = []
    plurals = 0
    for word in text.split():
        if plurals < MAX_PLURALS and not is_function_word(word) and not word.endswith("s"):
            choices.append([word, word + "s"])
            plurals += 1
        else:
            choices.append([word])
    return [" ".join(said) for said in itertools.product(*choices)]


class Decoding(Protocol):
    """A recognizer's decoder on one utterance, several texts at once (a batch)."""

    def first(self) -> np.ndarray:
        """The log-probabilities of the first token (one row)."""
        ...

    def then(self, parents: np.ndarray, tokens: np.ndarray) -> np.ndarray:
        """Texts ``parents`` (rows of the last call) each followed by ``tokens``: the
        log-probabilities of the token after each (one row per text)."""
        ...


@dataclass(frozen=True)
class Found:
    """A phrase a search wrote, and its log-probability (tokens and end, natural log)."""

    text: str
    log_prob: float


def closest_phrase(
    decoding: Decoding,
    grammar: PhraseGrammar,
    pieces: Sequence[str],
    *,
    end_token: int,
    max_tokens: int,
    at_least: float = -math.inf,
) -> Found | None:
    """The likeliest phrase of ``grammar`` the decoder writes (a beam of :data:`BEAM`
    texts), or None when none is finished within ``max_tokens`` or as likely as
    ``at_least`` (natural log: a phrase less likely is of no use, so the search drops the
    texts that fall below it). ``pieces[token]`` is the text a token writes ("" for tokens
    that write none)."""
    found = closest_phrases(
        decoding, grammar, pieces, end_token=end_token, max_tokens=max_tokens, at_least=at_least
    )
    return found[0] if found else None


def closest_phrases(
    decoding: Decoding,
    grammar: PhraseGrammar,
    pieces: Sequence[str],
    *,
    end_token: int,
    max_tokens: int,
    at_least: float = -math.inf,
    keep: int = 1,
    near: float = math.inf,
    floor_for: Callable[[int], float] | None = None,
    beam: int = BEAM,
) -> list[Found]:
    """The ``keep`` likeliest distinct phrases of ``grammar`` the decoder writes, likeliest
    first (see :func:`closest_phrase`): with ``keep=2``, how far the best stands above the
    next, which tells a phrase heard from one of two alike. ``near`` (natural log): only
    phrases at most this much less likely than the best are looked for, which ends the
    search sooner. ``floor_for``: the least likely (natural log) a phrase of so many words may
    be, which a text on the way to phrases of at most so many words need not fall below.
    ``beam``: how many texts are carried on at each step."""
    beams: list[tuple[str, float]] = [("", 0.0)]
    rows = decoding.first()
    top = min(TOP_TOKENS, rows.shape[1])
    finished: dict[str, float] = {}
    for _ in range(max_tokens):
        options: list[tuple[float, int, int, str]] = []
        for row, (text, score) in enumerate(beams):
            log_probs = rows[row]
            if grammar.complete(text):
                ended = score + float(log_probs[end_token])
                phrase = spelled(text).strip()
                if ended >= at_least and ended > finished.get(phrase, -math.inf):
                    finished[phrase] = ended
            for token in np.argpartition(-log_probs, top - 1)[:top]:
                piece = pieces[int(token)]
                if piece and np.isfinite(log_probs[token]) and grammar.allows(text + piece):
                    options.append((score + float(log_probs[token]), row, int(token), text + piece))
        options.sort(reverse=True)
        # a text's score only falls as it grows: one below the keep-th phrase never passes it
        ranked = sorted(finished.values(), reverse=True)
        floor = at_least if len(ranked) < keep else max(at_least, ranked[keep - 1])
        if ranked:
            floor = max(floor, ranked[0] - near)
        kept = [o for o in options[:beam] if o[0] > floor]
        if floor_for is not None:
            kept = [o for o in kept if o[0] > floor_for(grammar.most_words(o[3]))]
        if not kept:
            break
        rows = decoding.then(
            np.array([o[1] for o in kept]), np.array([o[2] for o in kept], dtype=np.int64)
        )
        beams = [(o[3], o[0]) for o in kept]
    best = sorted(finished.items(), key=lambda item: item[1], reverse=True)[:keep]
    return [Found(grammar.written(text), log_prob) for text, log_prob in best]


def bears_out(
    found: Found, free_log_prob: float, heard: Sequence[tuple[str, float]], grammar: PhraseGrammar
) -> bool:
    """Whether the audio bears out ``found``: nearly as likely as the free transcript
    (``free_log_prob``, natural log), and nothing in what was freely heard (``heard``: each
    word and its probability) clearly said that the phrase leaves out."""
    if found.log_prob < free_log_prob - CLOSE_ENOUGH_NATS:
        return False
    phrase = words(found.text)
    said = [(word, probability) for text, probability in heard for word in words(text)]
    for word, probability in said:
        if (
            word in grammar.keywords
            and probability >= KEYWORD_HEARD
            and not any(same_word(word, other) for other in phrase)
        ):
            return False
    return not any(
        probability >= CLEARLY_HEARD and not is_function_word(word)
        for word, probability in left_out(said, phrase)
    )


def sure_of(found: Found, heard: Sequence[tuple[str, float]]) -> bool:
    """Whether a phrase :func:`bears_out` accepted needs no second opinion (see
    :data:`SURE_PER_WORD`). Nor is a phrase sure that only adds meaning words to what was
    written ("What is your", trailing off, is not surely "what is your name")."""
    said = words(found.text)
    if not heard or len(said) < 2 or found.log_prob / (len(said) + 1) < SURE_PER_WORD:
        return False
    added: list[str] = []
    at = 0
    for word in (word for text, _ in heard for word in words(text)):
        while at < len(said) and not same_word(word, said[at]):
            added.append(said[at])
            at += 1
        if at == len(said):
            return True  # a word written that the phrase has nothing for: heard wrong
        at += 1
    return all(is_function_word(word) for word in [*added, *said[at:]])


def left_out(heard: Sequence[tuple[str, float]], phrase: Sequence[str]) -> list[tuple[str, float]]:
    """The words of ``heard`` (each with its probability) that the phrase has nothing for,
    in the alignment with the fewest changes (a word heard in place of one of the phrase's
    is a mishearing, not left out; a word the phrase repeats is not left out)."""
    rows, cols = len(heard), len(phrase)
    cost = [
        [row + col if row == 0 or col == 0 else 0 for col in range(cols + 1)]
        for row in range(rows + 1)
    ]
    for row in range(1, rows + 1):
        for col in range(1, cols + 1):
            change = 0 if same_word(heard[row - 1][0], phrase[col - 1]) else 1
            cost[row][col] = min(
                cost[row - 1][col] + 1, cost[row][col - 1] + 1, cost[row - 1][col - 1] + change
            )
    extra: list[int] = []
    row, col = rows, cols
    while row > 0 or col > 0:
        if (
            row > 0
            and col > 0
            and cost[row][col]
            == cost[row - 1][col - 1] + (0 if same_word(heard[row - 1][0], phrase[col - 1]) else 1)
        ):
            row, col = row - 1, col - 1
        elif row > 0 and cost[row][col] == cost[row - 1][col] + 1:
            extra.append(row - 1)
            row -= 1
        else:
            col -= 1
    return [heard[k] for k in extra if not any(same_word(heard[k][0], w) for w in phrase)]
