"""SQLite files encrypted at rest with the site's key (SQLCipher).

Why SQLCipher (``sqlcipher3-binary``): a recording stays a SQLite database that the robot
writes row by row while the session runs, yet every page on disk is AES-256 encrypted
and authenticated (HMAC-SHA512): no SQLite header, no readable phrase, and a changed byte
is detected, not read as data. A crash loses at most the last batch, as before; nothing
plain ever touches the disk. Encrypting a finished file instead (AES-GCM, age) would keep
the session plain on disk while it is recorded.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import sqlcipher3  # type: ignore[import-untyped]

from engine.errors import ConfigError
from engine.privacy.site_data import SiteKey

SQLITE_HEADER = b"SQLite format 3\x00"


def connect_sealed(path: Path, key: SiteKey, *, read_only: bool = False) -> Any:
    """A connection to the encrypted database at ``path`` (made when missing, unless
    ``read_only``). ConfigError naming the file when it cannot be read with ``key``: a
    plain (unencrypted) file, another site's, or one changed since it was written."""
    if read_only and not path.is_file():
        raise ConfigError(f"{path}: no such recording")
    target = f"file:{path}?mode=ro" if read_only else str(path)
    connection = sqlcipher3.connect(target, uri=read_only, check_same_thread=False)
    connection.execute("PRAGMA cipher_log_level = NONE")  # the message below says it once
    connection.execute(f"PRAGMA key = \"x'{key.hex()}'\"")
    try:
        connection.execute("SELECT count(*) FROM sqlite_master").fetchone()
    except sqlcipher3.DatabaseError:
        connection.close()
        raise ConfigError(_why_unreadable(path)) from None
    return connection


def _why_unreadable(path: Path) -> str:
    with open(path, "rb") as file:
        plain = file.read(len(SQLITE_HEADER)) == SQLITE_HEADER
    if plain:
        return f"{path}: a plain SQLite file, not encrypted with this site's key"
    return (
        f"{path}: cannot be read with this site's key: recorded at another site, or "
        "changed or damaged since it was written"
    )
