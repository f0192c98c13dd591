"""XML read with the place of every element, for messages a person can follow
(file:line:column), with limits a hostile file cannot get past (expat: no external
entities are fetched; at most :data:`MAX_ELEMENTS` elements)."""

from __future__ import annotations

import xml.parsers.expat
from dataclasses import dataclass, field

from engine.files.problems import LoadError, Mark, Problem

MAX_ELEMENTS = 10_000


@dataclass
class Element:
    tag: str
    attributes: dict[str, str]
    mark: Mark
    children: list[Element] = field(default_factory=list)


def parse_xml(text: str, name: str) -> Element:
    """The document's root element, each element with its place; LoadError at the place
    of a syntax error."""
    parser = xml.parsers.expat.ParserCreate()
    stack: list[Element] = []
    top: list[Element] = []
    count = [0]

    def start(tag: str, attributes: dict[str, str]) -> None:
        count[0] += 1
        if count[0] > MAX_ELEMENTS:
            raise ValueError(f"more than {MAX_ELEMENTS} elements")
        mark = Mark(name, parser.CurrentLineNumber, parser.CurrentColumnNumber + 1)
        element = Element(tag, dict(attributes), mark)
        (stack[-1].children if stack else top).append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as error:
        where = Mark(name, error.lineno, error.offset + 1)
        why = xml.parsers.expat.ErrorString(error.code)
        raise LoadError([Problem(where, f"not XML: {why}")]) from None
    except ValueError as error:
        raise LoadError([Problem(Mark(name, 1, 1), f"too big: {error}")]) from None
    return top[0]
