"""``vest data export`` and ``vest data erase``: what the site holds about one person,
handed over or removed (a family's rights of access and erasure, GDPR arts. 15 and 17).

An export is a folder, the owner's alone, holding each session as JSON (every table of the
recording, decrypted), its report as HTML, the person's consent record, their entries in
the index and the audit lines about them; it is listed as written about the person, so an
erasure removes it too. An erasure removes the recordings, reports and exports, the index
entries and the consent record, and leaves one audit line.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from engine.cli.output import tell, write_file
from engine.errors import ConfigError, UsageError
from engine.privacy.site import Site
from engine.recording.replay import Recording
from engine.recording.report import report_html
from engine.recording.session_file import TABLES

README = """What vest held about {person} on {day}, exported at the site's request.

sessions/*.json   each recorded session: every table of the recording, decrypted
reports/*.html    each session's report for the therapist (printable)
consent.json      the consent record ({consent})
index.json        the site's index entries of these sessions
audit.json        who recorded, replayed, reported, exported what about {person}, and when

This folder is not encrypted: keep it as the clinic keeps paper records, and remove it when
it has been handed over (vest data erase --person {person} removes it with the rest).
"""


def export(site: Site, args: argparse.Namespace) -> int:
    person: str = args.person
    sessions = site.records.sessions(person)
    folder: Path = args.output or Path(f"{person}-export")
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise ConfigError(f"-o {folder}: is there already; name a new folder")
    if not sessions and site.consents.records.get(person) is None:
        raise ConfigError(f"the site holds nothing about {person} ({site.folder})")
    for entry in sessions:  # every file is the person's, before anything is written
        if entry.path.is_file():
            recording = Recording.open(entry.path, site.key)
            try:
                site.check_belongs(entry.path, recording.meta.get("person", ""))
            finally:
                recording.close()
    try:
        (folder / "sessions").mkdir(mode=0o700, parents=True, exist_ok=True)
        (folder / "reports").mkdir(mode=0o700, exist_ok=True)
        folder.chmod(0o700)
    except OSError as error:
        raise ConfigError(f"-o {folder}: cannot make it ({error.strerror or error})") from None
    held = [entry.path for entry in sessions]  # listed first: an erasure or purge finds it
    site.output_written(folder, person, "export", held)
    missing = 0
    for number, entry in enumerate(sessions, 1):
        if not entry.path.is_file():
            tell(f"warning: {entry.path}: not there; left out of the export")
            missing += 1
            continue
        stem = f"{number:03d}-{entry.path.stem}"
        recording = Recording.open(entry.path, site.key)
        try:
            data: dict[str, Any] = {"file": str(entry.path)}
            data |= {name: recording.table(name) for name in (*TABLES, "events")}
            _write(folder / "sessions" / f"{stem}.json", data)
            page = report_html(recording)
        finally:
            recording.close()
        write_file(
            folder / "reports" / f"{stem}.html",
            page.encode(),
            str(folder),
            "a report",
            private=True,
        )
    consent = site.consent_of(person)
    _write(
        folder / "consent.json",
        {
            "person": person,
            "given_by": consent.given_by or None,
            "given_on": consent.given_on.isoformat() if consent.given_on else None,
            "until": consent.until.isoformat() if consent.until else None,
            "covers": sorted(consent.covers),
            "in_words": consent.describe(),
        },
    )
    _write(
        folder / "index.json",
        [
            {
                "file": str(e.path),
                "started": e.started,
                "length_s": e.length_s,
                "profile": e.profile,
                "kept": list(e.kept),
            }
            for e in sessions
        ],
    )
    lines = [line for line in site.records.audit_lines() if line.person == person]
    _write(folder / "audit.json", [_audit_line(line) for line in lines])
    day = site.today().isoformat()
    text = README.format(person=person, day=day, consent=consent.describe())
    write_file(folder / "README.txt", text.encode(), str(folder), "the export", private=True)
    count = len(sessions) - missing
    print(f"exported {count} session{'' if count == 1 else 's'} of {person} to {folder}")
    return 0


def _audit_line(line: Any) -> dict[str, Any]:
    return {"at": line.at, "who": line.who, "action": line.action, "what": line.what}


def _write(path: Path, data: Any) -> None:
    text = json.dumps(data, indent=1, default=str, allow_nan=False)
    write_file(path, text.encode("utf-8"), str(path), "the export", private=True)


def erase(site: Site, args: argparse.Namespace) -> int:
    person: str = args.person
    sessions = site.records.sessions(person)
    outputs = site.records.outputs(person)
    has_consent = person in site.consents.records
    if not sessions and not outputs and not has_consent:
        print(f"the site holds nothing about {person}")
        return 0
    if not args.yes:
        _confirm(person, len(sessions), len(outputs), has_consent)
    erased = site.erase(person)
    for path in erased.already_gone:
        tell(f"already gone: {path}")
    if erased.not_removed:
        for path, why in erased.not_removed:
            tell(f"could not remove {path} ({why}): remove it by hand")
        tell(f"the erasure of {person} is not finished: vest finishes it on its next run")
        return 1
    files = f"{len(erased.removed)} file{'' if len(erased.removed) == 1 else 's'}"
    consent = " and consent record" if has_consent else ""
    kept = "the audit trail keeps its lines about them, and one for this erasure"
    print(f"erased {person}: {files} removed, their index entries{consent} forgotten ({kept})")
    return 0


def _confirm(person: str, sessions: int, outputs: int, consent: bool) -> None:
    """Asks on the terminal; UsageError when there is none to ask on or the answer is no."""
    held = f"{sessions} recordings, {outputs} reports and exports" + (
        ", a consent record" if consent else ""
    )
    if not sys.stdin.isatty():
        raise UsageError(f"erasing {person} ({held}) cannot be undone: add --yes to confirm")
    tell(f"erase everything held about {person} ({held})? This cannot be undone.")
    tell(f"type {person} to confirm: ", sys.stderr)
    answer = sys.stdin.readline().strip()
    if answer != person:
        raise UsageError(f"not erased ({person} was not typed)")
