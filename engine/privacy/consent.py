"""Consent records: what a person's guardians agreed the robot may keep about them.

The site keeps one YAML file, ``consent.yaml`` in its data folder, one entry a pseudonym::

    kid-17:
      given_by: guardian        # who gave it: a role (guardian, parent, self), never a name
      given_on: 2026-11-20      # the day it was given (YYYY-MM-DD)
      covers: [sensors, speech_text, cloud_telemetry]
      until: 2027-11-20         # optional: the last day it holds

What a record may cover (:data:`CAPTURES`): ``sensors`` (touch, force, distance, gesture,
temperature readings and what the camera counted), ``speech_text`` (what the person said,
as text), ``audio``, ``camera`` (frames), ``cloud_telemetry`` (sensor readings sent to the
cloud service). A person with no record, or one that has ended, gets
:data:`WITHOUT_CONSENT`: sensor readings and the robot's own actions only. The robot still
answers whatever is consented: consent decides what is *kept and sent*, never what the
robot does.
"""

from __future__ import annotations

import contextlib
import datetime
import fcntl
import os
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import yaml

from engine.files.problems import Mark, Problems
from engine.files.whole_file import write_whole
from engine.files.yaml_source import load_yaml
from engine.files.yaml_values import YList, YMap, YScalar, YValue, plain
from engine.privacy.site_data import OWNER_ONLY_FILE
from engine.values.param_problems import did_you_mean

PSEUDONYM = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,39}")
"""A pseudonym: 1..40 letters, digits, '-', '_' or '.', starting with a letter or digit
(kid-17): never a name, which has a space."""
ROLE = re.compile(r"[A-Za-z][A-Za-z-]{0,39}")
"""Who gave consent, as a role: guardian, parent, self, legal-guardian."""
CONSENT_FILE = "consent.yaml"
CONSENT_LOCK = "consent.lock"
"""Held while the consent file is read and written again (:func:`editing_consent`)."""
CAPTURES: dict[str, str] = {
    "sensors": "sensor readings",
    "speech_text": "speech as text",
    "audio": "audio",
    "camera": "camera frames",
    "cloud_telemetry": "telemetry to the cloud",
}
"""What a consent record may cover, and how the timeline names each."""
WITHOUT_CONSENT = frozenset({"sensors"})
"""What is kept of a person with no consent record: sensor readings (and the robot's
actions, which are always kept)."""
FIELDS = ("given_by", "given_on", "covers", "until")


@dataclass(frozen=True)
class Consent:
    """What ``person`` agreed to (``covers``, names from :data:`CAPTURES`); ``given_by``
    and ``given_on`` are empty for the default of a person with no record."""

    person: str
    covers: frozenset[str]
    given_by: str = ""
    given_on: datetime.date | None = None
    until: datetime.date | None = None
    ended_on: datetime.date | None = None
    """The last day of a record that has ended (what it kept no longer holds)."""

    def allows(self, capture: str) -> bool:
        return capture in self.covers

    @property
    def left_out(self) -> tuple[str, ...]:
        """What is not kept, in :data:`CAPTURES` order."""
        return tuple(name for name in CAPTURES if name not in self.covers)

    def describe(self) -> str:
        """One line for the timeline and ``vest data consent``."""
        kept = ", ".join(CAPTURES[name] for name in CAPTURES if name in self.covers) or "nothing"
        if self.given_by == SIMULATION:
            return "no person named, on the simulated vest: nobody's data, everything is kept"
        if self.ended_on is not None:
            return (
                f"{self.person}: their consent ended on {self.ended_on.isoformat()} (renew it "
                f"with vest data consent): keeps {kept} (and the robot's actions)"
            )
        if self.given_on is None:
            who = f"{self.person}: no consent record" if self.person else "no person named"
            return f"{who}: keeps {kept} (and the robot's actions)"
        until = f", until {self.until.isoformat()}" if self.until else ""
        return (
            f"{self.person}: consent given by {self.given_by} on {self.given_on.isoformat()}"
            f"{until}: keeps {kept} (and the robot's actions)"
        )


SIMULATION = "simulation"
"""Who "gave" the consent of a session that senses nobody (:func:`of_a_simulation`)."""


def without_record(person: str) -> Consent:
    return Consent(person, WITHOUT_CONSENT)


def of_a_simulation() -> Consent:
    """What is kept of a session with no person named, on a simulated vest in its
    simulated room (no microphone, no real camera): everything in it was scripted, so it
    holds nobody's data and everything is kept and shown."""
    return Consent("", frozenset(CAPTURES), given_by=SIMULATION)


class ConsentBook:
    """The site's consent records, by pseudonym."""

    def __init__(self, records: Mapping[str, Consent]) -> None:
        self.records = dict(records)

    def of(self, person: str, today: datetime.date) -> Consent:
        """What ``person`` consented to on ``today``: their record while it holds, else
        :data:`WITHOUT_CONSENT`."""
        record = self.records.get(person)
        if record is None:
            return without_record(person)
        if record.until is not None and today > record.until:
            return Consent(person, WITHOUT_CONSENT, ended_on=record.until)
        return record

    def forget(self, folder: Path, person: str) -> None:
        """Removes ``person``'s record from ``folder/consent.yaml``: the lines of its entry,
        the rest of the file as it was, comments included; a file written in flow style
        (``{kid-1: {...}, kid-2: {...}}``) is written again in block style without it,
        every other record kept (its comments are not)."""
        self.records.pop(person, None)
        path = folder / CONSENT_FILE
        with editing_consent(folder):
            if not path.exists():
                return
            document = load_yaml(path)
            if not isinstance(document, YMap) or person not in document:
                return
            others = [key for key in document.key_marks if key != person]
            kept = _without_lines_of(path, document, person)
            if _persons_in(kept) != others:  # entries share lines: flow style
                rest = {key: plain(value) for key, value in document.items() if key != person}
                kept = (
                    yaml.safe_dump(rest, sort_keys=False, default_flow_style=False) if rest else ""
                )
            write_whole(path, kept.encode("utf-8"), mode=OWNER_ONLY_FILE)

    @classmethod
    def load(cls, folder: Path) -> ConsentBook:
        """The records in ``folder/consent.yaml`` (none when there is no such file);
        LoadError naming each mistake with its file:line:column."""
        path = folder / CONSENT_FILE
        if not path.exists():
            return cls({})
        return cls.load_file(path)

    @classmethod
    def load_file(cls, path: Path) -> ConsentBook:
        """The records in the consent file ``path``; LoadError at file:line:column."""
        document = load_yaml(path)
        problems = Problems()
        records: dict[str, Consent] = {}
        if document is None:
            return cls({})
        if not isinstance(document, YMap):
            problems.add(_mark(document), "a consent file maps each pseudonym to its record")
            problems.raise_if_any()
        assert isinstance(document, YMap)
        for person, entry in document.items():
            record = _record(person, entry, document.key_marks[person], problems)
            if record is not None:
                records[person] = record
        problems.raise_if_any()
        return cls(records)


def _mark(value: YValue) -> Mark:
    return value.mark


def _record(person: str, entry: YValue, where: Mark, problems: Problems) -> Consent | None:
    if not PSEUDONYM.fullmatch(person):
        problems.add(where, f"{person!r} is not a pseudonym", "e.g. kid-17: never a name")
        return None
    if not isinstance(entry, YMap):
        problems.add(_mark(entry), f"{person}: a consent record is a mapping", ", ".join(FIELDS))
        return None
    problems.unknown_fields(entry.key_marks, FIELDS, "consent")
    for needed in ("given_by", "given_on", "covers"):
        if needed not in entry:
            problems.add(where, f"{person}: no {needed!r}", "fields: " + ", ".join(FIELDS))
    given_by = entry.get("given_by")
    if given_by is not None and not (
        isinstance(given_by, YScalar)
        and isinstance(given_by.value, str)
        and ROLE.fullmatch(given_by.value)
    ):
        problems.add(
            _mark(given_by),
            "given_by: who gave consent, as a role (guardian, parent), never a name",
        )
    given_on = _day(entry.get("given_on"), "given_on", problems)
    until = _day(entry.get("until"), "until", problems)
    covers = _covers(entry.get("covers"), problems)
    if given_on is not None and until is not None and until < given_on:
        problems.add(_mark(entry.entries["until"]), "until: before the day consent was given")
    if covers is None or given_on is None or not isinstance(given_by, YScalar):
        return None
    return Consent(person, covers, str(given_by.value), given_on, until)


def _day(value: YValue | None, field: str, problems: Problems) -> datetime.date | None:
    if value is None:
        return None
    if isinstance(value, YScalar):
        if isinstance(value.value, datetime.date):
            return value.value
        try:
            return datetime.date.fromisoformat(str(value.value))
        except ValueError:
            pass
    problems.add(_mark(value), f"{field}: a day as YYYY-MM-DD (e.g. 2026-11-20)")
    return None


def _covers(value: YValue | None, problems: Problems) -> frozenset[str] | None:
    if value is None:
        return None
    if not isinstance(value, YList):
        problems.add(_mark(value), "covers: a list, e.g. [sensors, speech_text]")
        return None
    names: set[str] = set()
    for item in value:
        name = item.value if isinstance(item, YScalar) else None
        if not isinstance(name, str) or name not in CAPTURES:
            hint = (did_you_mean(name, CAPTURES) if isinstance(name, str) else None) or (
                "one of: " + ", ".join(CAPTURES)
            )
            problems.add(_mark(item), f"covers: {name!r} is not something vest keeps", hint)
            continue
        names.add(name)
    return frozenset(names)


@contextlib.contextmanager
def editing_consent(folder: Path) -> Iterator[None]:
    """Held while ``consent.yaml`` is read and written again (``consent.lock``): two vests
    adding or forgetting records at once take turns, each reading what the other wrote."""
    with open(folder / CONSENT_LOCK, "a+b") as lock:
        os.chmod(lock.name, OWNER_ONLY_FILE)
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


def _without_lines_of(path: Path, document: YMap, person: str) -> str:
    """The text of ``path`` without the lines of ``person``'s entry."""
    lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
    starts = sorted(mark.line for mark in document.key_marks.values())
    first = document.key_marks[person].line
    after = [line for line in starts if line > first]
    end = after[0] - 1 if after else len(lines)
    return "".join(lines[: first - 1] + lines[end:])


def _persons_in(text: str) -> list[str]:
    """The persons a consent file's text holds records of, in order (none when it does not
    read as a mapping)."""
    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError:
        return []
    return [str(key) for key in document] if isinstance(document, dict) else []
