"""The slips people make in YAML, found where they are and said in plain words.

PyYAML reports where it got stuck, which is often after the mistake: an apostrophe inside
single quotes ends the text early, a quote left open swallows the lines after it, a node
written without its colon or a child without its ``- `` is noticed a line later. Each rule
here looks at the text around the error for one such slip and, when it finds it, names
the line of the mistake and what to write instead.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

LOOK_BACK_LINES = 15
_APOSTROPHE = re.compile(r"'[^'\n]*'[A-Za-z]")
_WORD_ALONE = re.compile(r"^(\s*)(?:-\s+)?([A-Z][A-Za-z]*)\s*$")
_WORD_THEN_BRACE = re.compile(r"^\s*(?:-\s+)?([A-Z][A-Za-z]*)\s+[{\[]")


@dataclass(frozen=True)
class Slip:
    """Where the mistake is (1-based line and column), what it is, how to fix it."""

    line: int
    column: int
    message: str
    hint: str


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def _open_double_quote(line: str) -> int | None:
    """The column (0-based) of a double quote left open on ``line``, outside comments."""
    inside, start, escaped = False, 0, False
    for index, char in enumerate(line):
        if inside:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                inside = False
        elif char == '"':
            inside, start = True, index
        elif char == "#" and (index == 0 or line[index - 1] == " "):
            break
        elif char == "'" and line[index - 1 : index] in (" ", "{", "[", ":", ""):
            end = line.find("'", index + 1)
            if end < 0:
                break
    return start if inside else None


def explain(text: str, line: int, problem: str, context: str | None) -> Slip | None:
    """The slip behind a YAML error PyYAML reported at ``line`` (1-based), or None."""
    lines = text.splitlines()
    if not 1 <= line <= len(lines) + 1:
        return None
    first = max(0, line - 1 - LOOK_BACK_LINES)
    here = lines[line - 1] if line <= len(lines) else ""
    above = lines[first : line - 1]
    for number in range(first, min(line, len(lines))):
        found = _APOSTROPHE.search(lines[number])
        if found:
            word = found.group(0).strip("'")
            return Slip(
                number + 1,
                found.start() + 1,
                f"the text in single quotes ends at the apostrophe of {word!r}...",
                'write text with an apostrophe in double quotes, e.g. "That\'s funny!"',
            )
    for number in range(min(line, len(lines))):  # a quote left open swallows many lines
        column = _open_double_quote(lines[number])
        if column is not None:
            return Slip(
                number + 1,
                column + 1,
                "this quote is not closed on its line",
                'close it with " before the end of the line; a quote inside is written \\"',
            )
    brace = _WORD_THEN_BRACE.match(here)
    if brace:
        word = brace.group(1)
        return Slip(
            line,
            here.index(word) + 1,
            f"{word!r} needs a colon after it",
            f"write {word}: {{...}}",
        )
    if "mapping values are not allowed" in problem and above:
        alone = _WORD_ALONE.match(above[-1])
        if alone and _indent(here) > len(alone.group(1)):
            word = alone.group(2)
            return Slip(
                line - 1,
                above[-1].index(word) + 1,
                f"{word!r} needs a colon after it",
                f"write {word}: and list its children below it",
            )
    stripped = here.lstrip(" ")
    if "expected <block end>" in problem and stripped.startswith("- ") and above:
        siblings = [text for text in above if _indent(text) == _indent(here)]
        if siblings and not siblings[-1].lstrip().startswith("- "):
            return Slip(
                line,
                _indent(here) + 1,
                "children after a node's options need 'children:'",
                "write children: on a line of its own above the first '- ' and indent the "
                "children under it",
            )
    if "expected <block end>" in problem and not stripped.startswith("- ") and above:
        siblings = [text for text in above if _indent(text) == _indent(here)]
        if siblings and siblings[-1].lstrip().startswith("- "):
            return Slip(
                line,
                _indent(here) + 1,
                "this line is not a list item like the ones above it",
                "start it with '- ', as each child of a Sequence, Selector or Parallel",
            )
    return None


def hint_for(problem: str) -> str | None:
    """A general hint for a YAML error no slip above explains."""
    if "\\t" in problem or "tab" in problem:
        return "indent with spaces, not tabs"
    if "mapping values are not allowed" in problem:
        return "put text containing ': ' in quotes"
    if "could not find expected ':'" in problem:
        return "each entry needs 'key: value'"
    if "expected <block end>" in problem or "did not find expected" in problem:
        return "check the indentation of this line and the one above"
    return None
