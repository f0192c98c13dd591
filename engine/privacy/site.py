"""A site (a clinic, a lab): its data folder, key, consent records, index of sessions and
audit trail, and what a site does with them: keep sessions as long as it said, erase a
person on request, rotate its key.

Settings, in ``site.yaml`` in the data folder (optional)::

    keep_sessions_days: 365     # sessions older than this are purged (default 365)

Times are seconds since the epoch (UTC) from the injected clock (an
:class:`~engine.clock.EpochClock` in use).
"""

from __future__ import annotations

import contextlib
import datetime
import fcntl
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from engine.blackboard.catalogue import KeyCatalogue
from engine.clock import Clock
from engine.errors import ConfigError
from engine.files.fields import settings
from engine.files.problems import Problems
from engine.files.yaml_source import load_yaml
from engine.privacy.consent import PSEUDONYM, Consent, ConsentBook
from engine.privacy.sealed_sqlite import connect_sealed, rekey
from engine.privacy.site_data import KEY_FILE, SiteKey, make_key_file, read_key_file, site_key
from engine.privacy.site_records import RECORDS_FILE, SessionEntry, SiteRecords
from engine.values.param_problems import CheckContext
from engine.values.params import Number, Param

SETTINGS_FILE = "site.yaml"
KEEP_DAYS = 365
NEW_KEY_FILE = "site.key.new"
DAY_S = 86_400.0


SITE_FIELDS = (
    Param("keep_sessions_days", Number(1e-5, None, "days"), float(KEEP_DAYS), "days kept"),
)
"""What ``site.yaml`` may say: how long a session's recording is kept before it is purged."""


@dataclass(frozen=True)
class SiteSettings:
    keep_sessions_days: float = KEEP_DAYS

    @classmethod
    def load(cls, folder: Path) -> SiteSettings:
        """``folder/site.yaml`` (defaults when missing); LoadError at file:line:column."""
        path = folder / SETTINGS_FILE
        if not path.exists():
            return cls()
        document = load_yaml(path)
        if document is None:
            return cls()
        problems = Problems()
        values = settings(document, SITE_FIELDS, "site", CheckContext(KeyCatalogue(())), problems)
        problems.raise_if_any()
        assert values is not None
        return cls(values["keep_sessions_days"])


@dataclass(frozen=True)
class Erased:
    """What an erasure removed: files (recordings, reports, exports), those that were
    already gone, and those it could not remove (with why: remove them by hand)."""

    person: str
    removed: list[Path]
    already_gone: list[Path]
    not_removed: list[tuple[Path, str]] = field(default_factory=list)


@dataclass
class Purged:
    """What a purge removed: the sessions older than the site keeps them, every report,
    progress report, export and conversion that held one of them, and what it could not
    remove (with why: remove it by hand; the next purge tries again)."""

    sessions: list[SessionEntry] = field(default_factory=list)
    outputs: list[Path] = field(default_factory=list)
    not_removed: list[tuple[Path, str]] = field(default_factory=list)


class Site:
    """The site whose data folder is ``folder``; ``who`` is the user acting (for the audit
    trail)."""

    def __init__(self, folder: Path, key: SiteKey, clock: Clock, who: str) -> None:
        self.folder, self.key, self.clock, self.who = folder, key, clock, who
        _owner_only(folder)
        self.settings = SiteSettings.load(folder)
        self.consents = ConsentBook.load(folder)
        self.rotation_cut_off = False
        """A key rotation began and did not finish: some recordings are on the new key
        (``vest data rekey`` finishes it)."""
        rotation = folder / NEW_KEY_FILE
        if rotation.exists():
            new = read_key_file(rotation)
            if _reads_with(folder / RECORDS_FILE, new):  # cut off at its very last step
                os.replace(rotation, folder / KEY_FILE)
                self.key = SiteKey(new.key, folder / KEY_FILE)
            else:
                self.rotation_cut_off = True
        self._lock = _SiteLock(folder)
        self.records = SiteRecords(folder, self.key)

    @classmethod
    def open(cls, folder: Path, *, clock: Clock, who: str, create: bool = True) -> Site:
        """The site in ``folder``: its key made on first use when ``create``."""
        return cls(folder, site_key(folder, create=create), clock, who)

    def close(self) -> None:
        self.records.close()
        self._lock.release()

    # -- sessions -----------------------------------------------------------------------
    def today(self) -> datetime.date:
        return datetime.datetime.fromtimestamp(self.clock.now(), datetime.UTC).date()

    def consent_of(self, person: str) -> Consent:
        return self.consents.of(person, self.today())

    def audit(self, action: str, person: str, what: str) -> None:
        self.records.audit(self.clock.now(), self.who, action, person, what)

    def session_started(self, path: Path, person: str, profile: str, kept: tuple[str, ...]) -> None:
        """Indexes a new recording (and audits it)."""
        where = path.resolve()
        self.records.add_session(where, person, self.clock.now(), profile, kept)
        self.audit("record", person, str(where))

    def session_ended(self, path: Path, length_s: float) -> None:
        self.records.end_session(path.resolve(), length_s)

    def output_written(
        self, path: Path, person: str, kind: str, sources: Sequence[Path] = ()
    ) -> None:
        """Notes a report, progress report, export or conversion written in the clear about
        ``person``, holding the recordings ``sources``: removed when any of them is purged,
        and when the person is erased."""
        where = path.resolve()
        held = [source.resolve() for source in sources]
        self.records.add_output(where, person, kind, self.clock.now(), held)
        self.audit(f"{kind} written", person, str(where))

    def reports_folder(self) -> Path:
        """Where reports about a person go unless told otherwise: ``reports/`` in the data
        folder (its owner's alone; never the current folder, where ``git add -A`` or a
        shared drive would take a child's report)."""
        folder = self.folder / "reports"
        folder.mkdir(mode=0o700, exist_ok=True)
        return folder

    def check_belongs(self, recording: Path, person_in_file: str) -> None:
        """ConfigError when the index lists ``recording`` as another person's than the
        file says it is (a recording copied over another)."""
        entry = self.records.session_at(recording.resolve())
        if not PSEUDONYM.fullmatch(person_in_file):  # earlier vests took any name: no one
            person_in_file = ""
        if entry is not None and entry.person != person_in_file:
            listed = entry.person or "no one"
            said = person_in_file or "no one"
            raise ConfigError(
                f"{recording}: holds a session of {said}, but the site's index lists this file "
                f"as {listed}'s (a recording copied over another?); not read"
            )

    def person_of(self, recording: Path, person_in_file: str = "") -> str:
        """The pseudonym a recording belongs to: the index's, else (a copy moved or copied
        away from where it was recorded) the one the file says, sealed with the site's key
        ('' for none)."""
        entry = self.records.session_at(recording.resolve())
        if entry is not None:
            return entry.person
        return person_in_file if PSEUDONYM.fullmatch(person_in_file) else ""

    def check_not_erased(self, recording: Path, person: str, started: float) -> None:
        """ConfigError when ``person`` was erased after ``recording`` (started at
        ``started``, seconds since the epoch) began: a copy the erasure could not find."""
        if not person:
            return
        for line in self.records.audit_lines():
            if line.action == "erase" and line.person == person and line.at >= started:
                raise ConfigError(
                    f"{recording}: a copy of a session of {person}, whose data was erased "
                    f"on {_day(line.at)}; not read (remove it; vest data rekey makes every "
                    "copy made with the old key unreadable)"
                )

    # -- retention ----------------------------------------------------------------------
    def purge(self) -> Purged:
        """Removes every session older than the site keeps them: its file, its index entry,
        and every report, progress report, export and conversion that holds it (each
        audited); says what it could not remove."""
        oldest = self.clock.now() - self.settings.keep_sessions_days * DAY_S
        purged = Purged([entry for entry in self.records.sessions() if entry.started < oldest])
        days = self.settings.keep_sessions_days
        for entry in purged.sessions:
            failed = False
            for output in self.records.outputs_holding(entry.path):
                why = _removed(output)
                if why is not None:
                    purged.not_removed.append((output, why))
                    failed = True
                    continue
                self.records.forget_output(output)
                purged.outputs.append(output)
                self.audit("purge", entry.person, f"{output} (it held {entry.path})")
            why = _removed(entry.path)
            if why is not None:
                purged.not_removed.append((entry.path, why))
            elif not failed:  # else still listed: the next purge tries its copies again
                self.records.forget_session(entry.path)
                self.audit("purge", entry.person, f"{entry.path} (older than {days:g} days)")
        return purged

    # -- erasure ------------------------------------------------------------------------
    def erase(self, person: str) -> Erased:
        """Removes everything held about ``person``: recordings, reports, exports, the
        index's entries and the consent record, leaving one audit line. Marked first, so
        an erasure cut off half-way finishes on the next run (:meth:`finish_erasures`)."""
        self.records.begin_erasing(person, self.clock.now())
        return self._erase(person)

    def finish_erasures(self) -> list[Erased]:
        """Finishes erasures that were cut off."""
        return [self._erase(person) for person in self.records.unfinished_erasures()]

    def _erase(self, person: str) -> Erased:
        erased = Erased(person, [], [])
        paths = [e.path for e in self.records.sessions(person)]
        paths += [path for path, _ in self.records.outputs(person)]
        for path in paths:
            there = path.exists() or path.is_symlink()
            why = _removed(path)
            if why is not None:
                erased.not_removed.append((path, why))
            else:
                (erased.removed if there else erased.already_gone).append(path)
        if erased.not_removed:  # marked still: the next vest data or vest run tries again
            return erased
        self.consents.forget(self.folder, person)
        what = f"{len(erased.removed)} files removed"
        self.records.finish_erasing(person, (self.clock.now(), self.who, what))
        return erased

    # -- the key ------------------------------------------------------------------------
    def rekey(self, *, drop_missing: bool = False) -> tuple[list[Path], list[Path]]:
        """Encrypts the site's records and every indexed recording with a new key, then
        retires the old one; returns (re-encrypted, missing). Cut off, it is run again:
        files already on the new key are left as they are. ConfigError listing recordings
        that are not where the index says (moved, on a USB stick) unless
        ``drop_missing``: with the old key gone, those could never be read again."""
        sessions = self.records.sessions()
        missing = [entry.path for entry in sessions if not entry.path.is_file()]
        if missing and not drop_missing:
            raise ConfigError(
                f"{len(missing)} recording(s) not where the index says ({missing[0]}...): "
                "put them back, or add --drop-missing to give them up (they could never be "
                "read again)"
            )
        self._lock.alone()  # no other vest reads or records with the old key meanwhile
        new = site_key_in_rotation(self.folder)
        done: list[Path] = []
        self.records.close()
        # the site's records last: while they are on the old key, the rotation is unfinished
        for path in [*(e.path for e in sessions if e.path.is_file()), self.folder / RECORDS_FILE]:
            if _reads_with(path, new):
                continue
            rekey(path, self.key, new)
            done.append(path)
        os.replace(new.path, self.folder / KEY_FILE)
        self.key = SiteKey(new.key, self.folder / KEY_FILE)
        self.records = SiteRecords(self.folder, self.key)
        for path in missing:
            self.records.forget_session(path)
            self.audit("rekey", "", f"{path}: missing, given up")
        self.audit("rekey", "", f"{len(done)} files on a new key")
        self._lock.shared()
        return done, missing


class _SiteLock:
    """Every vest using a site holds its lock shared (``site.lock``, released when the
    process ends, however it ends); rotating the key needs it alone: never while a session
    is being recorded or a recording read with the old key."""

    def __init__(self, folder: Path) -> None:
        self.path = folder / "site.lock"
        self._file = open(self.path, "a+b")  # noqa: SIM115 - held for the site's lifetime
        os.chmod(self.path, 0o600)
        fcntl.flock(self._file, fcntl.LOCK_SH)

    def alone(self) -> None:
        try:
            fcntl.flock(self._file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ConfigError(
                f"{self.path.parent}: another vest is using this site now (a session being "
                "recorded, a replay or a report); run vest data rekey once it has ended"
            ) from None

    def shared(self) -> None:
        fcntl.flock(self._file, fcntl.LOCK_SH)

    def release(self) -> None:
        self._file.close()


def _day(at_s: float) -> str:
    return datetime.datetime.fromtimestamp(at_s, datetime.UTC).strftime("%Y-%m-%d")


def site_key_in_rotation(folder: Path) -> SiteKey:
    """The new key of a rotation under way (``site.key.new``), made when there is none."""
    path = folder / NEW_KEY_FILE
    try:
        return make_key_file(path)
    except FileExistsError:
        return read_key_file(path)


def _owner_only(folder: Path) -> None:
    """The data folder and the files a person writes in it become their owner's alone (a
    folder made by hand with 0755, a consent.yaml saved 0644)."""
    for path, mode in (
        (folder, 0o700),
        (folder / "consent.yaml", 0o600),
        (folder / SETTINGS_FILE, 0o600),
    ):
        try:
            if path.exists() and path.stat().st_mode & 0o077 and path.stat().st_uid == os.getuid():
                path.chmod(mode)
        except OSError:
            continue  # another user's: reading it says what is wrong


def _reads_with(path: Path, key: SiteKey) -> bool:
    try:
        connect_sealed(path, key, read_only=True).close()
    except ConfigError:
        return False
    return True


EXPORT_FILES = (
    "README.txt",
    "consent.json",
    "index.json",
    "audit.json",
    "sessions/*.json",
    "reports/*.html",
    "[0-9][0-9][0-9]-robot.wav",
)
"""What vest writes into a folder about a person (``vest data export``; ``vest run
--audio-out``: the robot's voice): an erasure or purge removes these, and the folder
when nothing else is left in it."""


def _removed(path: Path) -> str | None:
    """Removes ``path`` (:func:`_remove`); None when it is gone, else why it could not."""
    try:
        _remove(path)
    except OSError as error:
        return error.strerror or str(error)
    return None


def _remove(path: Path) -> bool:
    """Removes a file (and its SQLite journal), or what an export wrote in a folder (the
    folder too when nothing else is in it); False when it was not there, OSError when it
    cannot be removed."""
    if path.is_dir() and not path.is_symlink():
        for pattern in EXPORT_FILES:
            for written in path.glob(pattern):
                written.unlink(missing_ok=True)
        for folder in (path / "sessions", path / "reports", path):
            with contextlib.suppress(OSError):  # not empty: what someone else put there
                folder.rmdir()
        return True
    journal = path.with_name(path.name + "-journal")
    journal.unlink(missing_ok=True)
    if not (path.exists() or path.is_symlink()):
        return False
    path.unlink()
    return True
