"""Write a recorded session (`vest run --record FILE`) as a report a therapist reads: what
the person did and how the robot answered, how fast; how often each behaviour acted; what
it did not understand; devices that dropped out; the sensors over the session. One HTML
file with its pictures inside, printable on A4.

With --person PSEUDONYM instead of a file: that person's progress across every session the
site holds of them (vest data list --person): what they did, how the robot answered and
how fast, what it did not understand, per behaviour, session by session.
"""

from __future__ import annotations

import argparse
import unicodedata
from pathlib import Path

from engine.cli.output import tell, write_file
from engine.cli.site_access import open_recording, open_site, pseudonym
from engine.errors import ConfigError, UsageError
from engine.privacy.site import Site
from engine.recording.progress import SessionSummary, progress_html, summarize
from engine.recording.replay import Recording
from engine.recording.report import report_html
from engine.recording.report_page import REPORT_HEAD


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "recording", type=Path, nargs="?", metavar="FILE", help="made by vest run --record"
    )
    parser.add_argument(
        "--person",
        type=pseudonym,
        default=None,
        metavar="PSEUDONYM",
        help="instead of one FILE: the person's progress across their sessions",
    )
    parser.add_argument(
        "--with-simulated",
        action="store_true",
        help="with --person: count their simulated sessions too (on the simulated vest, "
        "a scenario or the buttons page played the child; left out by default), marked",
    )
    parser.add_argument(
        "--note",
        type=_note,
        default="",
        metavar="TEXT",
        help="the therapist's note, put at the top of the report (a blank line between "
        'paragraphs; from a file: --note "$(cat note.txt)")',
    )
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        metavar="REPORT.html",
        help="default: FILE with .html; a progress report goes into the site's data folder "
        "(reports/PSEUDONYM-progress.html), never the current folder",
    )


MAX_NOTE = 20_000
"""Characters a note may have (pages of text; a longer one is a file given by mistake)."""


def _note(text: str) -> str:
    if len(text) > MAX_NOTE:
        raise argparse.ArgumentTypeError(
            f"is {len(text):,} characters; a note has at most {MAX_NOTE:,}"
        )
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise argparse.ArgumentTypeError("is not UTF-8 text: give it as plain text") from None
    if any(unicodedata.category(c) == "Cc" and c not in "\n\t\r" for c in text):
        raise argparse.ArgumentTypeError("holds control characters: give it as plain text")
    return text


def main(args: argparse.Namespace) -> int:
    if (args.recording is None) == (args.person is None):
        raise UsageError("name a recording FILE, or --person PSEUDONYM for their progress")
    if args.person is not None:
        if args.note:
            raise UsageError("--note goes with one session's FILE, not --person")
        return _progress(args.person, args.output, with_simulated=args.with_simulated)
    recording, site = open_recording(args.recording, "report")
    try:
        output = args.output or args.recording.with_suffix(".html")
        check_replaceable(output, site)
        page = report_html(recording, args.note)
        cut = recording.cut_short
        write_file(output, page.encode("utf-8"), f"{output}", "the report", private=True)
        if site is not None:  # a report names the person in the clear: erased with them
            person = site.person_of(args.recording, recording.meta.get("person", ""))
            site.output_written(output, person, "report", [args.recording])
    finally:
        recording.close()
        if site is not None:
            site.close()
    print(f"report: {output}")
    if cut is not None:  # the report is written, and says so too
        tell(f"vest report: {cut}")
        return 1
    return 0


def check_replaceable(output: Path, site: Site | None) -> None:
    """ConfigError when ``output`` holds something a report would replace that is not a
    report vest wrote (a recording, someone's notes): never lost to a mistyped -o."""
    if not output.is_file():  # nothing there, or what writing it refuses by name (a FIFO)
        return
    if site is not None and site.records.is_output(output.resolve()):
        return
    try:
        with open(output, "rb") as file:
            head = file.read(200)
    except OSError:
        head = b""
    if head.startswith(REPORT_HEAD.encode()):
        return
    raise ConfigError(
        f"-o {output}: holds something else than a report, which the report would replace; "
        "name another file"
    )


def _progress(person: str, given: Path | None, *, with_simulated: bool) -> int:
    site = open_site(create=False)
    try:
        output = given or site.reports_folder() / f"{person}-progress.html"
        check_replaceable(output, site)
        entries = site.records.sessions(person)
        if not entries:
            raise UsageError(f"the site holds no session of {person} (vest data list)")
        summaries: list[SessionSummary] = []
        gone: list[Path] = []
        for entry in entries:
            if not entry.path.is_file():
                gone.append(entry.path)
                continue
            recording = Recording.open(entry.path, site.key)
            try:
                site.check_belongs(entry.path, recording.meta.get("person", ""))
                summaries.append(summarize(recording, entry.started))
            finally:
                recording.close()
            site.audit("report", person, str(entry.path))
        counted = [s for s in summaries if with_simulated or not s.simulated]
        page = progress_html(person, counted, gone, left_out=len(summaries) - len(counted))
        write_file(output, page.encode("utf-8"), f"{output}", "the report", private=True)
        held = [entry.path for entry in entries if entry.path not in gone]
        site.output_written(output, person, "progress report", held)
    finally:
        site.close()
    sessions = f"{len(counted)} session{'' if len(counted) == 1 else 's'}"
    left = len(summaries) - len(counted)
    simulated = (
        f" ({left} simulated session{'' if left == 1 else 's'} left out: --with-simulated "
        "counts them)"
        if left
        else ""
    )
    print(f"progress of {person} over {sessions}{simulated}: {output}")
    for path in gone:
        tell(f"warning: {path}: not there any more; left out of the progress")
    return 0
