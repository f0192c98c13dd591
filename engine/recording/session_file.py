"""The session recording file: one SQLite database, encrypted with the site's key
(:mod:`engine.privacy.sealed_sqlite`; docs/view-and-recordings.md describes it).

Times are seconds since the session started (its first tick's clock time). Tables:

- ``meta``: ``format`` (this module's :data:`FORMAT_VERSION`), when it was recorded, the
  robot config, the profile, how long it lasted, and how many changes were lost;
- ``trees``: each tree as it was run, one row per version (a hot reload adds one): its
  file, the SHA-256 of its files, its rate, its YAML source and its Graphviz drawing;
- ``nodes``: each node of each tree version, numbered in depth-first order as
  ``vest render`` numbers them (``n0`` is the root), with its path, type and (format 4
  on) what it does in plain words;
- ``statuses``: a node's status (and feedback message) each time it changes after a tick;

(format 2 on: ``seq`` in ``blackboard``, ``actions``, ``world`` and ``events`` numbers the
session's events in the order they happened, across tables)
- ``blackboard``: each write that changed a key's value, and every event, as JSON;
- ``events`` (format 3): every other event of the session as itself, its message of
  :mod:`engine.session.codec` in ``data``: actions and how they ended, what happened
  around the robot, what was heard and seen, devices, turns, safety, presses, pauses,
  sentences not understood or not listened to, reloads, the end.

A later version of vest reads every earlier format; it refuses a newer one by name.
Format 2 kept actions (``actions``, with ``outcome``, ``ended_s``, ``why``), the
scenario's events (``world``) in tables of their own and the rest of the account in
``events`` as fields; what was heard and seen and the devices came from the blackboard.
Format 1 (before the session's events were kept) has no ``events`` table and no outcome
of an action but its error. Recordings made before they were sealed are plain SQLite: they
are still read (:attr:`Opened.plain` says so), and ``vest data seal`` encrypts them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from engine.errors import ConfigError
from engine.privacy.sealed_sqlite import (
    Connection,
    Error,
    check_every_page,
    connect_plain,
    connect_sealed,
    could_be_sealed,
    is_plain_sqlite,
)
from engine.privacy.site_data import SiteKey, check_apart

FORMAT_VERSION = 4
TABLES = ("meta", "trees", "nodes", "statuses", "blackboard", "actions", "world")
"""The tables every format has (format 2 adds ``events``; from format 3 on, ``actions`` and
``world`` stay empty: their events are in ``events``)."""
SCHEMA = """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE trees (
    tree TEXT NOT NULL, version INTEGER NOT NULL, at_s REAL NOT NULL, file TEXT NOT NULL,
    digest TEXT NOT NULL, rate_hz REAL NOT NULL, source TEXT NOT NULL, dot TEXT NOT NULL,
    PRIMARY KEY (tree, version)
);
CREATE TABLE nodes (
    tree TEXT NOT NULL, version INTEGER NOT NULL, node INTEGER NOT NULL,
    path TEXT NOT NULL, type TEXT NOT NULL, label TEXT NOT NULL, depth INTEGER NOT NULL,
    words TEXT NOT NULL,
    PRIMARY KEY (tree, version, node)
);
CREATE TABLE statuses (
    at_s REAL NOT NULL, tree TEXT NOT NULL, version INTEGER NOT NULL, tick INTEGER NOT NULL,
    node INTEGER NOT NULL, status TEXT NOT NULL, feedback TEXT NOT NULL
);
CREATE INDEX statuses_by_time ON statuses (at_s);
CREATE TABLE blackboard (
    at_s REAL NOT NULL, key TEXT NOT NULL, value TEXT NOT NULL, event INTEGER NOT NULL,
    seq INTEGER
);
CREATE INDEX blackboard_by_time ON blackboard (at_s);
CREATE TABLE actions (
    at_s REAL NOT NULL, tree TEXT NOT NULL, action TEXT NOT NULL, args TEXT NOT NULL,
    error TEXT, action_id INTEGER, outcome TEXT, ended_s REAL, why TEXT, seq INTEGER,
    ended_seq INTEGER
);
CREATE INDEX actions_by_id ON actions (action_id);
CREATE TABLE world (
    at_s REAL NOT NULL, kind TEXT NOT NULL, description TEXT NOT NULL, seq INTEGER
);
CREATE TABLE events (
    at_s REAL NOT NULL, kind TEXT NOT NULL, tree TEXT NOT NULL, data TEXT NOT NULL,
    seq INTEGER
);
CREATE INDEX events_by_time ON events (at_s);
"""


def check_new(path: Path, key: SiteKey) -> None:
    """ConfigError unless a recording can be made at ``path``: never over a file that is
    there (an earlier session is never lost), never as a folder, never beside the key."""
    if path.is_dir():
        raise ConfigError(f"--record {path}: is a folder; name a file")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ConfigError(f"--record {path}: cannot write a recording there (no folder {folder})")
    if path.exists() or path.is_symlink():
        what = "an earlier session" if _is_recording(path, key) else "something else"
        raise ConfigError(
            f"--record {path}: holds {what}, which a new recording would replace; name "
            "another file (or remove that one first)"
        )
    try:
        check_apart(path, key)
    except ConfigError as error:
        raise ConfigError(f"--record {error}") from None


def create(path: Path, key: SiteKey) -> Connection:
    """A new, empty recording at ``path``, encrypted with ``key``; ConfigError when a file
    is there already, or the folder is missing or not writable."""
    check_new(path, key)
    try:
        connection = connect_sealed(path, key)
        connection.executescript(SCHEMA)
        connection.execute("INSERT INTO meta VALUES ('format', ?)", (str(FORMAT_VERSION),))
        connection.commit()
    except (OSError, Error, ConfigError) as error:
        raise ConfigError(f"--record {path}: cannot write a recording there ({error})") from None
    return connection


def _is_recording(path: Path, key: SiteKey) -> bool:
    """Whether ``path`` is a recording of this site (or a plain one of earlier vests)."""
    if not path.is_file():  # a FIFO would block the open until a writer came
        return False
    try:
        connection = connect_plain(path) if is_plain_sqlite(path) else None
        if connection is None:
            connection = connect_sealed(path, key, read_only=True)
        try:
            kind = connection.execute(
                "SELECT type FROM sqlite_master WHERE name = 'meta'"
            ).fetchone()
            if kind != ("table",):
                return False
            row = connection.execute("SELECT value FROM meta WHERE key = 'format'").fetchone()
        finally:
            connection.close()
    except (OSError, Error, ConfigError):
        return False
    return row is not None


def check_kind(path: Path) -> None:
    """ConfigError when ``path`` is missing or cannot be a recording (plain or sealed),
    before any key is looked for."""
    if not path.is_file():
        raise ConfigError(f"{path}: no such recording")
    if not (is_plain_sqlite(path) or could_be_sealed(path)):
        raise ConfigError(
            f"{path}: not a vest recording, or one cut short (its size is not whole pages of "
            "an encrypted database)"
        )


@dataclass(frozen=True)
class Opened:
    """A recording opened for reading: its connection, and whether the file is plain (made
    before recordings were sealed)."""

    connection: Connection
    plain: bool


def open_for_reading(path: Path, key: SiteKey | None) -> Opened:
    """An existing recording, read-only, decrypted with ``key``; ConfigError naming the
    file when it is not one, cannot be read with this key (another site's, changed or
    damaged: the encryption is authenticated) or without one (``key`` None: this machine
    has no site key), or is of a newer format than this vest reads."""
    check_kind(path)
    plain = is_plain_sqlite(path)
    if key is None and not plain:
        raise ConfigError(
            f"{path}: encrypted, and this machine has no site key to read it (set VEST_DATA "
            "to the data folder of the site that recorded it)"
        )
    journal = path.with_name(path.name + "-journal")
    if journal.exists():  # cut off mid-write: SQLite rolls the last batch back on opening
        try:
            # opened for writing once: a read-only connection cannot roll back
            recovering = (
                connect_sealed(path, key)
                if key is not None and not plain
                else connect_plain(path, False)
            )
            recovering.execute("SELECT count(*) FROM sqlite_master").fetchone()
            recovering.close()
        except Error as error:
            raise ConfigError(
                f"{path}: an interrupted recording that cannot be recovered ({error})"
            ) from None
    try:
        # one connection, used from the view's threads one query at a time (Recording locks)
        if key is not None and not plain:
            connection = connect_sealed(path, key, read_only=True)
            check_every_page(connection, path)  # tampering is named, never read as data
        else:
            connection = connect_plain(path)
        kinds = dict(connection.execute("SELECT name, type FROM sqlite_master").fetchall())
    except Error:
        raise ConfigError(f"{path}: not a vest recording (vest run --record makes them)") from None
    not_tables = sorted(name for name in (*TABLES, "events") if kinds.get(name, "table") != "table")
    if not_tables:  # a view in a table's place could ask anything of the reader (a loop)
        connection.close()
        raise ConfigError(f"{path}: not a vest recording ({not_tables[0]!r} is not a table)")
    try:
        row = connection.execute("SELECT value FROM meta WHERE key = 'format'").fetchone()
    except Error:
        raise ConfigError(f"{path}: not a vest recording (vest run --record makes them)") from None
    version = whole_number(row[0]) if row is not None else None
    if version is None:
        raise ConfigError(f"{path}: not a vest recording (it has no format number)")
    if version > FORMAT_VERSION:
        raise ConfigError(
            f"{path}: recorded in format {row[0]}, newer than this vest reads "
            f"({FORMAT_VERSION}); update vest"
        )
    missing = sorted(set(TABLES) - set(kinds))
    if missing:
        raise ConfigError(f"{path}: a damaged recording (no table {missing[0]!r})")
    _check_kinds_of_values(connection, path, set(kinds))
    return Opened(connection, plain)


def whole_number(value: object) -> int | None:
    """``value`` (a meta value: text) as a count or a format number, or None when it is
    not one: ASCII digits only, at most 18 of them (a damaged file may hold '²' or 5,000
    nines, which ``int`` refuses or takes long over)."""
    text = str(value)
    if not (0 < len(text) <= 18 and text.isascii() and text.isdigit()):
        return None
    return int(text)


TEXT, NUMBER, WHOLE = ("text",), ("real", "integer"), ("integer",)
COLUMNS: dict[str, dict[str, tuple[tuple[str, ...], bool]]] = {
    "meta": {"key": (TEXT, False), "value": (TEXT, False)},
    "trees": {
        "tree": (TEXT, False),
        "version": (WHOLE, False),
        "at_s": (NUMBER, False),
        "file": (TEXT, False),
        "rate_hz": (NUMBER, False),
        "dot": (TEXT, False),
    },
    "nodes": {
        "tree": (TEXT, False),
        "version": (WHOLE, False),
        "node": (WHOLE, False),
        "path": (TEXT, False),
        "type": (TEXT, False),
        "label": (TEXT, False),
        "depth": (WHOLE, False),
        "words": (TEXT, False),
    },
    "statuses": {
        "at_s": (NUMBER, False),
        "tree": (TEXT, False),
        "version": (WHOLE, False),
        "node": (WHOLE, False),
        "status": (TEXT, False),
        "feedback": (TEXT, False),
    },
    "blackboard": {"at_s": (NUMBER, False), "key": (TEXT, False), "value": (TEXT, False)},
    "actions": {
        "at_s": (NUMBER, False),
        "tree": (TEXT, False),
        "action": (TEXT, False),
        "args": (TEXT, False),
        "error": (TEXT, True),
        "outcome": (TEXT, True),
        "ended_s": (NUMBER, True),
        "why": (TEXT, True),
        "seq": (WHOLE, True),
        "ended_seq": (WHOLE, True),
    },
    "world": {"at_s": (NUMBER, False), "kind": (TEXT, False), "description": (TEXT, False)},
    "events": {
        "at_s": (NUMBER, False),
        "kind": (TEXT, False),
        "tree": (TEXT, False),
        "data": (TEXT, False),
        "seq": (WHOLE, True),
    },
}
"""What kind of value each column a reader uses holds (and whether it may be empty)."""
MAX_DEPTH = 1000


def _check_kinds_of_values(connection: Connection, path: Path, tables: set[str]) -> None:
    """ConfigError naming the first column that holds another kind of value than vest
    writes there (text where a time is, a picture's bytes where a name is): one query a
    table, so no reader meets such a value later."""
    for table, columns in COLUMNS.items():
        if table not in tables:
            continue  # format 1 has no events table
        present = {row[1] for row in connection.execute(f"PRAGMA table_info({table})")}
        for column, (kinds, empty) in columns.items():
            if column not in present:
                continue  # a column format 1 did not have
            allowed = ", ".join(f"'{kind}'" for kind in (*kinds, *(("null",) if empty else ())))
            try:
                wrong = connection.execute(
                    f"SELECT typeof({column}) FROM {table} "
                    f"WHERE typeof({column}) NOT IN ({allowed}) LIMIT 1"
                ).fetchone()
            except Error as error:
                raise ConfigError(f"{path}: a damaged recording ({error})") from None
            if wrong is not None:
                raise ConfigError(
                    f"{path}: a damaged recording ({table}.{column} holds {wrong[0]})"
                )
    deep = connection.execute(
        "SELECT depth FROM nodes WHERE depth < 0 OR depth > ? LIMIT 1", (MAX_DEPTH,)
    ).fetchone()
    if deep is not None:
        raise ConfigError(f"{path}: a damaged recording (a node at depth {deep[0]})")
