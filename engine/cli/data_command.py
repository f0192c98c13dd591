"""The site's data: whose sessions it holds, what each person consented to, and what the
site must be able to do with it (docs/privacy.md).

  vest data list [--person P] [--json]     each session: person, date, length, profile, file
  vest data consent [PERSON]               the consent records (consent.yaml), checked
  vest data consent PERSON --given-by ROLE --covers sensors,speech_text [--on DAY] [--until DAY]
  vest data purge                          remove sessions older than the site keeps them
  vest data export --person P [-o DIR]     everything held about P: sessions as JSON, reports
  vest data erase --person P [--yes]       remove everything held about P (asks first)
  vest data audit [--person P] [--json]    who recorded, replayed, reported, exported, erased
  vest data rekey [--drop-missing]         encrypt everything with a new key
  vest data seal FILE...                   encrypt recordings made before vest sealed them
The site's data folder is $VEST_DATA, else ~/.local/share/vest (made on first use, the
owner's alone). It holds the key: losing it is losing every recording made with it.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import sys
from pathlib import Path

from engine.cli.data_export import erase, export
from engine.cli.output import tell
from engine.cli.site_access import open_site, pseudonym
from engine.errors import ConfigError, UsageError
from engine.files.problems import LoadError
from engine.files.whole_file import write_whole
from engine.privacy.consent import (
    CAPTURES,
    CONSENT_FILE,
    PSEUDONYM,
    ROLE,
    ConsentBook,
    editing_consent,
)
from engine.privacy.sealed_sqlite import is_plain_sqlite, seal_copy
from engine.privacy.site import Site
from engine.privacy.site_data import OWNER_ONLY_FILE, check_apart
from engine.recording.replay import Recording


def _day(text: str) -> datetime.date:
    try:
        return datetime.date.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a day as YYYY-MM-DD, got {text!r}") from None


def _covers(text: str) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    wrong = [name for name in names if name not in CAPTURES]
    if wrong or not names:
        raise argparse.ArgumentTypeError(
            f"{wrong[0] if wrong else text!r}: not something vest keeps; one or more of "
            + ", ".join(CAPTURES)
        )
    return list(dict.fromkeys(names))  # "sensors,sensors" is one


def add_arguments(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    listing = actions.add_parser("list", help="each session the site holds, by person")
    listing.add_argument("--person", type=pseudonym, help="only this person's sessions")
    listing.add_argument("--json", action="store_true", help="one JSON object per session")
    consent = actions.add_parser("consent", help="show, check or add consent records")
    consent.add_argument("person", nargs="?", type=pseudonym, help="one person's record")
    consent.add_argument("--given-by", metavar="ROLE", help="who gave it: guardian, parent...")
    consent.add_argument("--covers", type=_covers, help="comma-separated: " + ", ".join(CAPTURES))
    consent.add_argument("--on", type=_day, metavar="DAY", help="the day given (default today)")
    consent.add_argument("--until", type=_day, metavar="DAY", help="the last day it holds")
    actions.add_parser("purge", help="remove sessions older than the site keeps them")
    exporting = actions.add_parser("export", help="write everything held about a person")
    exporting.add_argument("--person", type=pseudonym, required=True)
    exporting.add_argument("-o", "--output", type=Path, metavar="DIR", help="default PERSON-export")
    erasing = actions.add_parser("erase", help="remove everything held about a person")
    erasing.add_argument("--person", type=pseudonym, required=True)
    erasing.add_argument("--yes", action="store_true", help="do not ask (for scripts)")
    audit = actions.add_parser("audit", help="who recorded, replayed, exported, erased what")
    audit.add_argument("--person", type=pseudonym, help="only lines about this person")
    audit.add_argument("--json", action="store_true", help="one JSON object per line")
    rekey = actions.add_parser("rekey", help="encrypt the site's data with a new key")
    rekey.add_argument(
        "--drop-missing",
        action="store_true",
        help="give up recordings that are not where the index says (never readable again)",
    )
    seal = actions.add_parser("seal", help="encrypt recordings made before vest sealed them")
    seal.add_argument("files", type=Path, nargs="+", metavar="FILE")


def main(args: argparse.Namespace) -> int:
    site = open_site()
    try:
        for erased in site.finish_erasures():
            tell(f"finished erasing {erased.person} (cut off earlier)")
        handler = {
            "list": _list,
            "consent": _consent,
            "purge": _purge,
            "export": export,
            "erase": erase,
            "audit": _audit,
            "rekey": _rekey,
            "seal": _seal,
        }[args.action]
        return handler(site, args)
    finally:
        site.close()


def when(at: float) -> str:
    """A stored time (seconds since the epoch) as a person reads it, UTC ('?' for one no
    calendar has)."""
    try:
        return datetime.datetime.fromtimestamp(at, datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    except (OverflowError, OSError, ValueError):
        return "?"


def _list(site: Site, args: argparse.Namespace) -> int:
    sessions = site.records.sessions(args.person)
    if args.json:
        for entry in sessions:
            print(
                json.dumps(
                    {
                        "person": entry.person,
                        "started": entry.started,
                        "length_s": entry.length_s,
                        "profile": entry.profile,
                        "kept": list(entry.kept),
                        "file": str(entry.path),
                        "present": entry.path.is_file(),
                    }
                )
            )
        return 0
    if not sessions:
        print("no sessions" + (f" of {args.person}" if args.person else "") + f" in {site.folder}")
        return 0
    print(f"{'person':<14}{'started':<22}{'length':>9}  profile / file")
    for entry in sessions:
        length = f"{entry.length_s:.0f} s" if entry.length_s is not None else "unfinished"
        gone = "" if entry.path.is_file() else "  (not there)"
        profile = Path(entry.profile).stem if entry.profile else "-"
        person = entry.person or "(none)"
        print(f"{person:<14}{when(entry.started):<22}{length:>9}  {profile}  {entry.path}{gone}")
    return 0


def _consent(site: Site, args: argparse.Namespace) -> int:
    if args.given_by is not None or args.covers is not None:
        return _add_consent(site, args)
    records = site.consents.records
    if args.person is not None:
        print(site.consent_of(args.person).describe())
        return 0
    print(f"{site.folder / CONSENT_FILE}: {len(records)} records, no mistakes")
    for person in sorted(records):
        print("  " + site.consent_of(person).describe())
    return 0


def _add_consent(site: Site, args: argparse.Namespace) -> int:
    if args.person is None or args.given_by is None or args.covers is None:
        raise UsageError("vest data consent PERSON --given-by ROLE --covers LIST: all three")
    if not ROLE.fullmatch(args.given_by) or args.given_by != args.given_by.lower():
        raise UsageError(
            f"--given-by {args.given_by!r}: a role in lower case (guardian, parent, self), "
            "never a name"
        )
    given_on = args.on or site.today()
    if args.until is not None and args.until < given_on:
        raise UsageError(
            f"--until {args.until.isoformat()}: before the day consent was given "
            f"({given_on.isoformat()})"
        )
    path = site.folder / CONSENT_FILE
    lines = [
        f"{args.person}:",
        f"  given_by: {args.given_by}",
        f"  given_on: {given_on.isoformat()}",
        f"  covers: [{', '.join(args.covers)}]",
    ]
    if args.until is not None:
        lines.append(f"  until: {args.until.isoformat()}")

    def reads_back(written: Path) -> None:
        """Never saved unless the whole file reads back (its mistakes named in the file's
        own name, not the temporary one's)."""
        try:
            ConsentBook.load_file(written)
        except LoadError as error:
            shown = str(error).replace(str(written), str(path))
            raise ConfigError(f"{path}: not changed: with {args.person} added,\n{shown}") from None

    with editing_consent(site.folder):  # another vest adding meanwhile takes its turn
        if args.person in ConsentBook.load(site.folder).records:  # as it is now
            raise ConfigError(f"{path}: {args.person} has a record already; change it in that file")
        before = path.read_text(encoding="utf-8") if path.exists() else ""
        separator = "" if not before or before.endswith("\n") else "\n"
        text = before + separator + "\n".join(lines) + "\n"
        write_whole(path, text.encode("utf-8"), mode=OWNER_ONLY_FILE, check=reads_back)
    site.audit("consent", args.person, f"given by {args.given_by}: {', '.join(args.covers)}")
    print(f"{path}: added {args.person}")
    return 0


def _purge(site: Site, args: argparse.Namespace) -> int:
    purged = site.purge()
    days = site.settings.keep_sessions_days
    for entry in purged.sessions:
        print(f"purged {entry.path} ({entry.person or 'no person'}, {when(entry.started)})")
    for output in purged.outputs:
        print(f"removed {output} (it held a purged session)")
    print(f"{_count(len(purged.sessions), 'session')} older than {days:g} days removed")
    return told_not_removed(purged.not_removed)


def told_not_removed(not_removed: list[tuple[Path, str]]) -> int:
    """Says, by name, each file that could not be removed and why (1), or nothing (0)."""
    for path, why in not_removed:
        tell(f"could not remove {path} ({why}): remove it by hand; vest tries again next time")
    return 1 if not_removed else 0


def _count(number: int, thing: str) -> str:
    return f"{number} {thing}{'' if number == 1 else 's'}"


def _number(text: str | None) -> float | None:
    """A meta value as a finite number, else None."""
    try:
        value = float(text) if text is not None else None
    except ValueError:
        return None
    return value if value is not None and math.isfinite(value) else None


def _audit(site: Site, args: argparse.Namespace) -> int:
    lines = site.records.audit_lines()
    broken = next((line for line in lines if not line.intact), None)
    for line in lines:
        if args.person is not None and line.person != args.person:
            continue
        if args.json:
            fields = {k: getattr(line, k) for k in ("seq", "at", "who", "action", "person")}
            print(json.dumps({**fields, "what": line.what, "intact": line.intact}))
        else:
            person = f" {line.person}" if line.person else ""
            print(f"{line.seq:>5}  {when(line.at)}  {line.who}  {line.action}{person}: {line.what}")
    if lines and args.person is None and not args.json:
        head = lines[-1]
        print(
            f"{len(lines)} lines; the last one's chain is {head.chain[:16]}: kept elsewhere, "
            "it shows whether lines were later removed from the end"
        )
    if broken is not None:
        tell(
            f"vest data audit: line {broken.seq} and after were changed after they were "
            "written (the chain breaks there)"
        )
        return 1
    return 0


def _rekey(site: Site, args: argparse.Namespace) -> int:
    done, missing = site.rekey(drop_missing=args.drop_missing)
    for path in missing:
        tell(f"given up: {path} (not there; it cannot be read with the new key)")
    print(f"{_count(len(done), 'file')} encrypted with a new key ({site.key.path})")
    tell(
        f"back up the new key now ({site.key.path}): the old one is gone, and copies of "
        "recordings made before (backups) can be read only with the old key's backup"
    )
    return 0


def _seal(site: Site, args: argparse.Namespace) -> int:
    for path in args.files:
        if path.is_symlink():  # sealing the link would leave the file it names in the clear
            raise ConfigError(f"{path}: a link; name the file itself ({path.resolve()})")
        if not path.is_file() or not is_plain_sqlite(path):
            raise ConfigError(f"{path}: not a plain recording (sealed already, or not one)")
        check_apart(path, site.key)
        Recording.open(path, None).close()  # a recording, not any SQLite file
        sealing = path.with_name(path.name + ".sealing")
        sealing.unlink(missing_ok=True)
        seal_copy(path, sealing, site.key)
        recording = Recording.open(sealing, site.key)
        meta = recording.meta
        recording.close()
        os.replace(sealing, path)
        person = meta.get("person", "")
        if person and not PSEUDONYM.fullmatch(person):
            tell(
                f"warning: {path}: names its person {person!r}, not a pseudonym; listed as no one's"
            )
            person = ""
        if site.records.session_at(path.resolve()) is None:  # listed, purged, erased as any
            now = site.clock.now()
            started = _number(meta.get("started"))
            if started is None or not 0 <= started <= now:  # purged from today on, not never
                tell(f"warning: {path}: no start time it could have had; listed as of now")
                started = now
            kept = tuple(name for name in meta.get("kept", "").split(",") if name)
            site.records.add_session(path.resolve(), person, started, meta.get("profile", ""), kept)
            if (length := _number(meta.get("duration_s"))) is not None and length >= 0:
                site.session_ended(path, length)
        site.audit("seal", person, str(path.resolve()))
        print(f"sealed {path}")
    sys.stdout.flush()
    return 0
