"""Write a recorded session (`vest run --record FILE`) as a report a therapist reads: what
the person did and how the robot answered, how fast; how often each behaviour acted; what
it did not understand; devices that dropped out; the sensors over the session. One HTML
file with its pictures inside, printable on A4.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.cli.output import tell, write_file
from engine.cli.site_access import open_recording
from engine.recording.report import report_html


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recording", type=Path, metavar="FILE", help="made by vest run --record")
    parser.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        metavar="REPORT.html",
        help="default: FILE with .html",
    )


def main(args: argparse.Namespace) -> int:
    recording, site = open_recording(args.recording, "report")
    try:
        page = report_html(recording)
        cut = recording.cut_short
        output = args.output or args.recording.with_suffix(".html")
        write_file(output, page.encode("utf-8"), f"{output}", "the report")
        if site is not None:  # a report names the person in the clear: erased with them
            site.output_written(output, site.person_of(args.recording), "report")
    finally:
        recording.close()
        if site is not None:
            site.close()
    print(f"report: {output}")
    if cut is not None:  # the report is written, and says so too
        tell(f"vest report: {cut}")
        return 1
    return 0
