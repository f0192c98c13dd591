"""A site's recordings are encrypted with its own key: made on first use, the owner's
alone, and a file copied elsewhere, made plain or changed on disk is named, never read."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from engine.errors import ConfigError
from engine.privacy.sealed_sqlite import connect_sealed
from engine.privacy.site_data import check_apart, data_folder, site_key


def test_the_data_folder_is_vest_data_else_the_user_s_own(tmp_path: Path) -> None:
    assert data_folder({"VEST_DATA": str(tmp_path / "clinic")}) == tmp_path / "clinic"
    assert data_folder({"XDG_DATA_HOME": "/x/share", "HOME": "/home/ana"}) == Path("/x/share/vest")
    assert data_folder({"HOME": "/home/ana"}) == Path("/home/ana/.local/share/vest")


def test_the_key_is_made_once_on_first_use_and_only_its_owner_may_read_it(
    tmp_path: Path,
) -> None:
    folder = tmp_path / "clinic"
    made = site_key(folder, create=True)
    assert stat.S_IMODE(made.path.stat().st_mode) == 0o600
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    assert site_key(folder, create=True) == made  # the same key next time
    made.path.chmod(0o644)
    with pytest.raises(ConfigError, match=r"others may read the site key .*chmod 600"):
        site_key(folder, create=False)


def test_a_missing_or_broken_key_is_named(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"no site key here, .*VEST_DATA"):
        site_key(tmp_path, create=False)
    (tmp_path / "site.key").write_text("not hex\n")
    (tmp_path / "site.key").chmod(0o600)
    with pytest.raises(ConfigError, match=r"site.key:1:1: not a site key \(64 hex digits\)"):
        site_key(tmp_path, create=False)


def test_a_sealed_file_holds_no_sqlite_header_and_no_readable_phrase(tmp_path: Path) -> None:
    key = site_key(tmp_path / "clinic", create=True)
    path = tmp_path / "session.vest"
    connection = connect_sealed(path, key)
    connection.execute("CREATE TABLE heard (text TEXT)")
    connection.execute("INSERT INTO heard VALUES ('my name is Lina and I like dogs')")
    connection.commit()
    connection.close()
    raw = path.read_bytes()
    assert not raw.startswith(b"SQLite format 3") and b"Lina" not in raw and b"dogs" not in raw
    reading = connect_sealed(path, key, read_only=True)
    assert reading.execute("SELECT text FROM heard").fetchall() == [
        ("my name is Lina and I like dogs",)
    ]
    reading.close()


def test_another_site_s_key_a_plain_file_or_a_changed_byte_is_named(tmp_path: Path) -> None:
    ours = site_key(tmp_path / "ours", create=True)
    theirs = site_key(tmp_path / "theirs", create=True)
    path = tmp_path / "session.vest"
    connection = connect_sealed(path, ours)
    connection.execute("CREATE TABLE t (x)")
    connection.commit()
    connection.close()
    with pytest.raises(ConfigError, match="cannot be read with this site's key"):
        connect_sealed(path, theirs, read_only=True)
    changed = bytearray(path.read_bytes())
    changed[100] ^= 1
    path.write_bytes(bytes(changed))
    with pytest.raises(ConfigError, match="changed or damaged since it was written"):
        connect_sealed(path, ours, read_only=True)
    plain = tmp_path / "plain.db"
    plain.write_bytes(b"SQLite format 3\x00" + bytes(4080))
    with pytest.raises(ConfigError, match="a plain SQLite file, not encrypted"):
        connect_sealed(plain, ours, read_only=True)


def test_a_recording_is_never_kept_beside_the_key(tmp_path: Path) -> None:
    key = site_key(tmp_path / "clinic", create=True)
    with pytest.raises(ConfigError, match="with its key; record elsewhere"):
        check_apart(tmp_path / "clinic" / "s.vest", key)
    check_apart(tmp_path / "s.vest", key)
