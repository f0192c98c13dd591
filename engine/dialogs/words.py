"""Words as the dialog matcher sees them: normalized, stemmed, and weighed by meaning.

A *function word* ("what", "is", "your", "please", "robot") shapes a question but does not
say what it is about; a *meaning word* ("name", "temperature", "cake", "not") does. The
matcher requires every meaning word of a phrase and forgives missing function words, so
"do you like cake" never matches "do you like animals". Words outside English have no
function-word list and all count as meaning words.
"""

from __future__ import annotations

import difflib
import itertools
import re
import unicodedata
from collections.abc import Sequence

_CONTRACTIONS = {
    "what's": "what is",
    "who's": "who is",
    "where's": "where is",
    "it's": "it is",
    "how's": "how is",
    "that's": "that is",
    "there's": "there is",
    "i'm": "i am",
    "i've": "i have",
    "i'd": "i would",
    "i'll": "i will",
    "you're": "you are",
    "you've": "you have",
    "what're": "what are",
    "don't": "do not",
    "doesn't": "does not",
    "didn't": "did not",
    "isn't": "is not",
    "aren't": "are not",
    "can't": "can not",
    "cannot": "can not",
    "won't": "will not",
    "haven't": "have not",
    "favourite": "favorite",
    "colour": "color",
    "colours": "colors",
}
_SPACES = re.compile(r"\s+")
_ONES = ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine"]
_TEENS = [
    "ten",
    "eleven",
    "twelve",
    "thirteen",
    "fourteen",
    "fifteen",
    "sixteen",
    "seventeen",
    "eighteen",
    "nineteen",
]
_TENS = ["_", "_", "twenty", "thirty", "forty", "fifty", "sixty", "seventy", "eighty", "ninety"]
_ORDINALS = {
    "one": "first",
    "two": "second",
    "three": "third",
    "five": "fifth",
    "eight": "eighth",
    "nine": "ninth",
    "twelve": "twelfth",
}
NUMBER_WORDS = frozenset([*_ONES, *_TEENS, *_TENS[2:], "hundred"])
_NUMBER = re.compile(r"^(\d+)(st|nd|rd|th)?$")
_WORD_CATEGORIES = ("L", "M", "N")
"""Letters, marks and digits of any script (marks: the vowel signs of Devanagari, accents)."""

_FUNCTION_WORD_LINES = (
    "a an the this that these those there here it its",
    "i me my mine we us our you your yours yourself he him his she her they them their",
    "is are am was were be been being do does did have has had will would shall should",
    "can could may might must",
    "what who whom whose which how why where when",
    "to of in on at for with about from by as into over",
    "and or but so if then than just really very too also",
    "please hey hi hello oh um uh er ah okay ok well robot tell say let know",
    "today now right again actually maybe still anyway though",
)
FUNCTION_WORDS = frozenset(" ".join(_FUNCTION_WORD_LINES).split())
"""Words that shape a question without saying what it is about. Negations ("no", "not",
"never") are not among them: they turn an answer around."""

QUESTION_WORDS = {
    "what": "what",
    "which": "what",
    "who": "who",
    "how": "how",
    "where": "where",
    "when": "when",
    "why": "why",
}
"""Question words, by what they ask: a phrase's question word must be heard ("what are you
doing" is not "how are you doing"); "which" asks what "what" asks."""

PERSON_WORDS = {
    **dict.fromkeys(("i", "me", "my", "mine", "myself"), "me"),
    **dict.fromkeys(("you", "your", "yours", "yourself"), "you"),
    **dict.fromkeys(("he", "him", "his", "himself"), "he"),
    **dict.fromkeys(("she", "her", "hers", "herself"), "she"),
    **dict.fromkeys(("we", "us", "our", "ours"), "we"),
    **dict.fromkeys(("they", "them", "their", "theirs"), "they"),
}
"""Whom a sentence is about: "what is *my* name" is not "what is *your* name". A phrase's
person must be heard, and another person heard counts as a meaning word the phrase lacks."""

NEGATIONS = frozenset({"not", "never", "no", "nobody", "nothing", "nowhere"})
"""Words that turn a sentence around."""
NEGATING_PREFIXES = ("un", "in", "im", "il", "ir", "dis", "non")
"""What turns a word into its opposite: "unfriendly", "incorrect", "impossible"."""
SLIP_MIN_LETTERS = 8
"""A word this long or longer may be misspelled by a letter or two and still be the word;
shorter ones are too often another word ("desert", "dessert"; "weather", "whether")."""
FUNCTION_WEIGHT = 0.3
"""How much a function word counts towards a phrase's coverage (a meaning word counts 1)."""


def _word_character(char: str) -> bool:
    return char == "'" or unicodedata.category(char)[0] in _WORD_CATEGORIES


def normalize(text: str) -> str:
    """Case folded, no punctuation, contractions spelled out, numbers as words, single
    spaces; in any script.

    Accents are kept (``café`` stays ``café``); both sides of a match are normalized the
    same way (Unicode NFKC), so a composed and a decomposed ``é`` are the same letter. What
    recognizers write their own way is written as a person writes a phrase: a hyphenated
    word joined ("Good-bye" is "goodbye"; "twenty-one" and "5-29" stay two numbers), a number
    in words ("6th" is "sixth", "21" "twenty one", a longer one digit by digit: "2287" is
    "two two eight seven").
    """
    folded = unicodedata.normalize("NFKC", text).casefold().replace("\u2019", "'")
    folded = re.sub(r"(?<=\w)-(?=\w)", _joined, folded)
    words = "".join(c if _word_character(c) else " " for c in folded).split()
    spelled = " ".join(_spelled(word) for word in words)
    expanded = " ".join(_CONTRACTIONS.get(word, word) for word in spelled.split())
    return _SPACES.sub(" ", expanded.replace("'", "")).strip()


def _joined(hyphen: re.Match[str]) -> str:
    """A hyphen between letters: nothing (one word), but between numbers a space."""
    text = hyphen.string
    before = re.findall(r"\w+$", text[: hyphen.start()])
    after = re.findall(r"^\w+", text[hyphen.end() :])
    numbers = before and after and all(_a_number(word[0]) for word in (before, after))
    return " " if numbers else ""


def _a_number(word: str) -> bool:
    """A number, as digits or words, or its ordinal ("seventieth", "twelfth")."""
    if word in NUMBER_WORDS or word.isdigit() or word in _ORDINALS.values():
        return True
    return word.endswith("th") and word[:-2].rstrip("ie") in {w.rstrip("ye") for w in NUMBER_WORDS}


def _spelled(word: str) -> str:
    """A number written in digits, in words (see :func:`normalize`); other words as they are."""
    found = _NUMBER.match(word)
    if found is None:
        return word
    digits, ordinal = found.groups()
    if len(digits) > 2 or (len(digits) == 2 and digits[0] == "0"):
        said = " ".join(_ONES[int(d)] for d in digits)
    else:
        value = int(digits)
        if value < 10:
            said = _ONES[value]
        elif value < 20:
            said = _TEENS[value - 10]
        else:
            said = _TENS[value // 10] + ("" if value % 10 == 0 else " " + _ONES[value % 10])
    if not ordinal:
        return said
    head, _, last = said.rpartition(" ")
    if last in _ORDINALS:
        last = _ORDINALS[last]
    elif last.endswith("y"):
        last = last[:-1] + "ieth"
    else:
        last = last + "th"
    return f"{head} {last}".strip()


def stem(word: str) -> str:
    """A plural's singular ("colors" -> "color", "puppies" -> "puppy"); other words (and
    function words: "does", "always") as they are."""
    if word in FUNCTION_WORDS or word.endswith(("ss", "us", "is", "ys")):
        return word
    if len(word) > 4 and word.endswith("ies"):
        return word[:-3] + "y"
    if len(word) > 3 and word.endswith("s"):
        return word[:-1]
    return word


def is_function_word(word: str) -> bool:
    return word in FUNCTION_WORDS


def weight(word: str) -> float:
    """1 for a meaning word, :data:`FUNCTION_WEIGHT` for a function word."""
    return FUNCTION_WEIGHT if is_function_word(word) else 1.0


def same_word(heard: str, expected: str) -> bool:
    """The same word, or a long word misspelled by a letter or two ("temprature"; of
    :data:`SLIP_MIN_LETTERS` letters or more, the same first letter, neither a number nor
    the other with a negating prefix), or a question word asking the same ("which" for
    "what")."""
    if heard == expected:
        return True
    if expected in QUESTION_WORDS:
        return QUESTION_WORDS.get(heard) == QUESTION_WORDS[expected]
    if expected in PERSON_WORDS:
        return PERSON_WORDS.get(heard) == PERSON_WORDS[expected]
    if min(len(heard), len(expected)) < SLIP_MIN_LETTERS or heard[0] != expected[0]:
        return False  # "desert" is not "dessert", "laughter" not "daughter"
    if any(
        one == prefix + other
        for one, other in ((heard, expected), (expected, heard))
        for prefix in NEGATING_PREFIXES
    ):
        return False  # "incorrect" is not "correct"
    if _a_number(heard) or _a_number(expected):
        return False  # "seventeenth" is not "seventieth"
    return difflib.SequenceMatcher(None, heard, expected).ratio() >= 0.85


def says_otherwise(written: Sequence[str], phrase: Sequence[str]) -> bool:
    """Whether ``written`` (words) names a person, asks a question or negates where
    ``phrase`` does not: "what is *my* name" is not "what is your name", "*why* is it cold"
    not "is it cold", "it is *not* cold" not "it is cold", however alike they sound."""
    for word in written:
        if any(same_word(word, other) for other in phrase):
            continue
        if word in PERSON_WORDS or word in QUESTION_WORDS or word in NEGATIONS:
            return True
    return False


def words(text: str) -> tuple[str, ...]:
    """The stemmed words of ``text`` after :func:`normalize`."""
    return tuple(stem(word) for word in normalize(text).split())


def written_as(heard: Sequence[str], phrase: Sequence[str]) -> tuple[str, ...]:
    """``heard`` (words) with its compounds written as ``phrase`` writes them: a recognizer's
    "good bye" or "foot ball" is the phrase's "goodbye" or "football", its "icecream" the
    phrase's "ice cream". Words the phrase has as they are stay as they are."""
    own = set(phrase)
    split = {a + b: (a, b) for a, b in itertools.pairwise(phrase)}
    written: list[str] = []
    at = 0
    while at < len(heard):
        word = heard[at]
        after = heard[at + 1] if at + 1 < len(heard) else None
        if word not in own and after is not None and after not in own and word + after in own:
            written.append(word + after)
            at += 2
            continue
        if word not in own and word in split:
            written.extend(split[word])
        else:
            written.append(word)
        at += 1
    return tuple(written)


def alike(one: str, other: str) -> float:
    """How alike two texts sound as written, 0 (nothing in common) to 1 (the same words):
    the share of letters in order the two :func:`words` spellings have in common ("can we
    play a game" and "can you play again" are 0.72, "what is your name" and "I like cats"
    0.15)."""
    return difflib.SequenceMatcher(None, " ".join(words(one)), " ".join(words(other))).ratio()
