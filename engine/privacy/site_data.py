"""The site's data folder and its key.

A site (a clinic, a lab) keeps what only it may read in one folder: the key every
recording is encrypted with, and (later) the index of sessions, the consent records and
the audit trail. ``VEST_DATA`` names the folder; otherwise it is the user's own
(``$XDG_DATA_HOME/vest``, else ``~/.local/share/vest``). The folder is made on first use,
readable by its owner only, and the key in it likewise: 32 random bytes, hex, one line.
Losing the key is losing every recording made with it (docs say so).
"""

from __future__ import annotations

import secrets
import stat
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from engine.errors import ConfigError
from engine.files.whole_file import write_whole

KEY_FILE = "site.key"
KEY_BYTES = 32
OWNER_ONLY_FOLDER = 0o700
OWNER_ONLY_FILE = 0o600


def data_folder(environment: Mapping[str, str]) -> Path:
    """Where the site keeps its data: ``VEST_DATA``, else the user's data folder."""
    named = environment.get("VEST_DATA", "").strip()
    if named:
        return Path(named).expanduser()
    base = environment.get("XDG_DATA_HOME", "").strip()
    home = Path(base).expanduser() if base else Path(environment.get("HOME", "~")) / ".local/share"
    return home.expanduser() / "vest"


@dataclass(frozen=True)
class SiteKey:
    """The site's key (32 bytes) and where it is kept."""

    key: bytes
    path: Path

    def hex(self) -> str:
        return self.key.hex()


def site_key(folder: Path, *, create: bool) -> SiteKey:
    """The key in ``folder``; made there on first use when ``create`` (the folder too,
    owner-only). ConfigError naming the file when it is missing (not ``create``), readable
    by others, or not a key."""
    path = folder / KEY_FILE
    if not path.exists():
        if not create:
            raise ConfigError(
                f"{path}: no site key here, so no recording of this site can be read "
                "(set VEST_DATA to the site's data folder)"
            )
        try:
            folder.mkdir(mode=OWNER_ONLY_FOLDER, parents=True, exist_ok=True)
        except OSError as error:
            why = error.strerror or error
            raise ConfigError(f"{folder}: cannot keep the site's data there ({why})") from None
        try:
            return make_key_file(path)
        except FileExistsError:  # another vest made it a moment ago: use that one
            pass
    return read_key_file(path)


def read_key_file(path: Path) -> SiteKey:
    """The key held in ``path``; ConfigError when others may read it or it is not a key."""
    if not path.is_file():
        raise ConfigError(f"{path}: is not a file; the site key is one line of hex")
    mode = stat.S_IMODE(path.stat().st_mode)
    if mode & 0o077:
        raise ConfigError(
            f"{path}: others may read the site key (mode {mode:o}); make it the owner's "
            f"alone: chmod 600 {path}"
        )
    text = path.read_text(encoding="ascii", errors="replace").strip()
    try:
        key = bytes.fromhex(text)
    except ValueError:
        key = b""
    if len(key) != KEY_BYTES:
        raise ConfigError(f"{path}:1:1: not a site key ({KEY_BYTES * 2} hex digits)")
    return SiteKey(key, path)


def make_key_file(path: Path) -> SiteKey:
    """A new random key written whole to ``path``, owner-only; FileExistsError when a file
    is there (two vests starting at once never write two keys over each other, and neither
    reads a key the other has only begun to write)."""
    key = secrets.token_bytes(KEY_BYTES)
    try:
        write_whole(path, (key.hex() + "\n").encode("ascii"), mode=OWNER_ONLY_FILE, exclusive=True)
    except FileExistsError:
        raise
    except OSError as error:
        why = error.strerror or error
        raise ConfigError(f"{path}: cannot write the site key there ({why})") from None
    return SiteKey(key, path)


def check_apart(recording: Path, key: SiteKey) -> None:
    """A recording is never written into the folder that holds the key, nor below it (a
    copy of one would carry the other)."""
    if recording.resolve().is_relative_to(key.path.resolve().parent):
        raise ConfigError(
            f"{recording}: is in the site's data folder, with its key; record elsewhere"
        )
