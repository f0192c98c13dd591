"""What every report page vest writes shares: how it begins, its style sheet, its tables,
the therapist's note, and that no control character reaches it (:func:`printable`)."""

from __future__ import annotations

import html
from pathlib import Path

REPORT_HEAD = '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">'
"""How every report vest writes begins (a file that does may be written over)."""
STYLE = (Path(__file__).resolve().parent / "report.css").read_text
"""The report's style sheet, read when a report is written (it goes inside the page)."""

_UNPRINTABLE = dict.fromkeys(
    [*range(0x09), 0x0B, 0x0C, *range(0x0E, 0x20), *range(0x7F, 0xA0)], "\ufffd"
)


def printable(page: str) -> str:
    """``page`` with each control character (NUL, ESC, C1...) shown as \ufffd, so a damaged
    or hand-made recording's text cannot put one in a page a supervisor opens."""
    return page.translate(_UNPRINTABLE)


def note_section(note: str) -> str:
    """The therapist's note as paragraphs ('' when there is none)."""
    paragraphs = [part.strip() for part in note.split("\n\n") if part.strip()]
    if not paragraphs:
        return ""
    body = "".join(f"<p>{html.escape(part)}</p>" for part in paragraphs)
    return f'<section class="note"><h2>The therapist\'s note</h2>{body}</section>'


def table(heads: list[str], rows: str, empty: str, *, numeric: set[int]) -> str:
    """A table with ``heads`` over ``rows`` (HTML), or one row saying ``empty``; the
    columns in ``numeric`` are right-aligned."""
    cells = "".join(
        f'<th class="num">{h}</th>' if i in numeric else f"<th>{h}</th>"
        for i, h in enumerate(heads)
    )
    body = rows or f"<tr><td colspan={len(heads)}>{html.escape(empty)}</td></tr>"
    return f"<table><thead><tr>{cells}</tr></thead><tbody>{body}</tbody></table>"
