"""SQLite files encrypted at rest with the site's key (SQLCipher).

Why SQLCipher (``sqlcipher3-binary``): a recording stays a SQLite database that the robot
writes row by row while the session runs, yet every page on disk is AES-256 encrypted
and authenticated (HMAC-SHA512): no SQLite header, no readable phrase, and a changed byte
is detected, not read as data. A crash loses at most the last batch, as before; nothing
plain ever touches the disk. Encrypting a finished file instead (AES-GCM, age) would keep
the session plain on disk while it is recorded.

Every connection here is a ``sqlcipher3`` one (the DB-API of :mod:`sqlite3`); its errors
are :data:`Error`, not :class:`sqlite3.Error`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import sqlcipher3  # type: ignore[import-untyped]

from engine.errors import ConfigError
from engine.privacy.site_data import SiteKey

SQLITE_HEADER = b"SQLite format 3\x00"
Error: type[Exception] = sqlcipher3.Error
"""What a sealed (or plain) connection raises: a damaged page, a full disk..."""
Connection = Any
"""A ``sqlcipher3`` connection: ``execute``, ``commit``, ``close`` as :mod:`sqlite3`'s."""


def is_plain_sqlite(path: Path) -> bool:
    """Whether ``path`` starts as an unencrypted SQLite file does (False when unreadable)."""
    try:
        with open(path, "rb") as file:
            return file.read(len(SQLITE_HEADER)) == SQLITE_HEADER
    except OSError:
        return False


def could_be_sealed(path: Path) -> bool:
    """Whether ``path`` has the shape of an encrypted database: whole pages of 1 KiB or a
    power of two more (a text file, an empty one, a picture has not). Only the key can
    tell more."""
    try:
        size = path.stat().st_size
    except OSError:
        return False
    return size > 0 and size % 1024 == 0


def connect_sealed(path: Path, key: SiteKey, *, read_only: bool = False) -> Connection:
    """A connection to the encrypted database at ``path`` (made when missing, unless
    ``read_only``). ConfigError naming the file when it cannot be read with ``key``: a
    plain (unencrypted) file, another site's, or one changed since it was written."""
    if read_only and not path.is_file():
        raise ConfigError(f"{path}: no such file")
    target = f"file:{path}?mode=ro" if read_only else str(path)
    try:
        connection = sqlcipher3.connect(target, uri=read_only, check_same_thread=False)
        connection.execute("PRAGMA cipher_log_level = NONE")  # the message below says it once
        connection.execute(f"PRAGMA key = \"x'{key.hex()}'\"")
        connection.execute("SELECT count(*) FROM sqlite_master").fetchone()
    except sqlcipher3.DatabaseError:
        raise ConfigError(_why_unreadable(path)) from None
    except sqlcipher3.Error as error:
        raise ConfigError(f"{path}: cannot be opened ({error})") from None
    return connection


def check_every_page(connection: Connection, path: Path) -> None:
    """ConfigError naming the first page of the sealed database that fails its check (a
    byte changed since it was written): every page is read once."""
    try:
        failed = connection.execute("PRAGMA cipher_integrity_check").fetchone()
    except sqlcipher3.Error as error:
        failed = (str(error),)
    if failed is not None:
        raise ConfigError(
            f"{path}: changed or damaged since it was written ({str(failed[0]).lower()})"
        )


def connect_plain(path: Path, read_only: bool = True) -> Connection:
    """A connection to an unencrypted SQLite file (a recording made before recordings
    were sealed); read-only unless asked."""
    target = f"file:{path}?mode=ro" if read_only else str(path)
    return sqlcipher3.connect(target, uri=read_only, check_same_thread=False)


def seal_copy(plain: Path, sealed: Path, key: SiteKey) -> None:
    """Writes ``sealed``: the whole of the plain database ``plain``, encrypted with ``key``
    (SQLCipher's ``sqlcipher_export``); ``sealed`` must not exist."""
    connection = sqlcipher3.connect(f"file:{plain}?mode=ro", uri=True)
    try:
        connection.execute(f"ATTACH DATABASE ? AS sealed KEY \"x'{key.hex()}'\"", (str(sealed),))
        connection.execute("SELECT sqlcipher_export('sealed')")
        connection.execute("DETACH DATABASE sealed")
    finally:
        connection.close()


def rekey(path: Path, old: SiteKey, new: SiteKey) -> None:
    """Encrypts the database at ``path`` with ``new`` instead of ``old`` (every page is
    written again; SQLite's journal keeps it whole if this is cut off)."""
    connection = connect_sealed(path, old)
    try:
        connection.execute(f"PRAGMA rekey = \"x'{new.hex()}'\"")
    finally:
        connection.close()


def _why_unreadable(path: Path) -> str:
    if is_plain_sqlite(path):
        return f"{path}: a plain SQLite file, not encrypted with this site's key"
    if not could_be_sealed(path):
        return f"{path}: not an encrypted database (its size is not whole pages)"
    return (
        f"{path}: cannot be read with this site's key: recorded at another site (or before "
        "this site's key was changed with vest data rekey), or changed or damaged since it "
        "was written"
    )
