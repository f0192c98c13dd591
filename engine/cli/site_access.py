"""The site this command works for: its data folder from ``VEST_DATA`` (else the user's
own), opened with its key (:mod:`engine.privacy.site`), and the recordings it reads."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from engine.cli.output import tell
from engine.cli.who import acting_user
from engine.clock import EpochClock
from engine.errors import ConfigError
from engine.privacy.consent import PSEUDONYM
from engine.privacy.sealed_sqlite import is_plain_sqlite
from engine.privacy.site import Site
from engine.privacy.site_data import data_folder
from engine.recording.replay import Recording
from engine.recording.session_file import check_kind


def pseudonym(text: str) -> str:
    """A pseudonym (argparse type): 1..40 letters, digits, '-', '_' or '.', starting with
    a letter or digit."""
    if not PSEUDONYM.fullmatch(text):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a pseudonym: use 1 to 40 letters, digits, '-', '_' or '.' "
            "(e.g. kid-17), never a person's name"
        )
    return text


def open_site(*, create: bool = True) -> Site:
    """The site of this machine's user (``VEST_DATA``); its key is made on first use when
    ``create``. ConfigError when its key or records cannot be read, or a consent record or
    setting has mistakes (file:line:column)."""
    site = Site.open(data_folder(os.environ), clock=EpochClock(), who=acting_user(), create=create)
    if site.rotation_cut_off:
        tell(f"warning: {site.folder}: a key rotation was cut off; run vest data rekey to finish")
    return site


def open_recording(path: Path, action: str) -> tuple[Recording, Site | None]:
    """The recording at ``path`` read with the site's key, its reading audited as
    ``action`` (replay, report...). A plain recording (made before they were sealed) is
    read without a key, with a warning."""
    check_kind(path)
    plain = is_plain_sqlite(path)
    try:
        site: Site | None = open_site(create=False)
    except ConfigError as error:
        if not plain:
            raise ConfigError(f"{path}: cannot be read here: {error}") from None
        site = None
    try:
        recording = Recording.open(path, site.key if site is not None else None)
    except BaseException:
        if site is not None:
            site.close()
        raise
    if recording.plain:
        tell(
            f"warning: {path} is not encrypted (recorded before vest sealed recordings): "
            f"vest data seal {path} encrypts it"
        )
    if site is not None:
        said = recording.meta.get("person", "")
        person = site.person_of(path, said)
        try:
            site.check_belongs(path, said)
            site.check_not_erased(path, person, _started(recording))
        except ConfigError:
            recording.close()
            site.close()
            raise
        site.audit(action, person, str(path.resolve()))
    return recording, site


def _started(recording: Recording) -> float:
    """When the session began (seconds since the epoch; 0 when the file does not say)."""
    try:
        return float(recording.meta.get("started", "0") or 0)
    except ValueError:
        return 0.0
