"""Every file vest rewrites (a tree the editor saves, the consent records, the record of
finished commands) is written whole: the old file or the new one, never a part, and
nobody else may read the new one before it is in place."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.files.whole_file import write_whole


def test_a_file_is_replaced_whole_and_keeps_its_mode(tmp_path: Path) -> None:
    tree = tmp_path / "hug.yaml"
    tree.write_text("old: 1\n", encoding="utf-8")
    tree.chmod(0o640)
    write_whole(tree, b"new: 2\n")
    assert tree.read_text(encoding="utf-8") == "new: 2\n"
    assert tree.stat().st_mode & 0o777 == 0o640
    assert [p.name for p in tmp_path.iterdir()] == ["hug.yaml"]  # nothing left beside it


def test_the_new_text_is_the_owner_s_alone_until_it_is_in_place(tmp_path: Path) -> None:
    seen: list[int] = []
    consent = tmp_path / "consent.yaml"
    write_whole(consent, b"kid-17: {}\n", mode=0o644, check=lambda p: seen.append(p.stat().st_mode))
    assert [mode & 0o777 for mode in seen] == [0o600]  # while it was checked
    assert consent.stat().st_mode & 0o777 == 0o644  # the mode asked for, once in place


def test_a_new_text_its_check_refuses_leaves_the_old_file_as_it_was(tmp_path: Path) -> None:
    consent = tmp_path / "consent.yaml"
    consent.write_text("kid-17:\n  covers: [sensors]\n", encoding="utf-8")

    def refuse(temporary: Path) -> None:
        raise ValueError(f"{temporary.name}: does not read back")

    with pytest.raises(ValueError, match="does not read back"):
        write_whole(consent, b"kid-17: [", check=refuse)
    assert consent.read_text(encoding="utf-8") == "kid-17:\n  covers: [sensors]\n"
    assert [p.name for p in tmp_path.iterdir()] == ["consent.yaml"]


def test_a_disk_that_fails_leaves_the_old_file_and_no_temporary_one(tmp_path: Path) -> None:
    done = tmp_path / "done.json"
    done.write_text("{}", encoding="utf-8")

    def full(temporary: Path) -> None:
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space left"):
        write_whole(done, b'{"cmd-1": {}}', check=full)
    assert done.read_text(encoding="utf-8") == "{}"
    assert [p.name for p in tmp_path.iterdir()] == ["done.json"]


def test_a_file_made_new_is_its_owner_s_alone_unless_told(tmp_path: Path) -> None:
    write_whole(tmp_path / "done.json", b"{}")
    write_whole(tmp_path / "tree.yaml", b"{}", mode=0o644)
    assert (tmp_path / "done.json").stat().st_mode & 0o777 == 0o600
    assert (tmp_path / "tree.yaml").stat().st_mode & 0o777 == 0o644


def test_a_file_reached_through_a_link_is_written_and_the_link_kept(tmp_path: Path) -> None:
    kept = tmp_path / "elsewhere" / "consent.yaml"
    kept.parent.mkdir()
    kept.write_text("old\n", encoding="utf-8")
    link = tmp_path / "consent.yaml"
    link.symlink_to(kept)
    write_whole(link, b"new\n")
    assert link.is_symlink() and kept.read_text(encoding="utf-8") == "new\n"


def test_a_file_made_only_where_none_is_appears_whole_or_not_at_all(tmp_path: Path) -> None:
    # the site key: two vests starting at once must keep one key, and neither may read
    # the other's before its last byte is written
    key = tmp_path / "site.key"
    seen_while_writing: list[bool] = []
    write_whole(
        key,
        b"ab" * 32 + b"\n",
        exclusive=True,
        check=lambda _: seen_while_writing.append(key.exists()),
    )
    assert seen_while_writing == [False]  # not there until it was whole
    with pytest.raises(FileExistsError):
        write_whole(key, b"cd" * 32 + b"\n", exclusive=True)
    assert key.read_bytes() == b"ab" * 32 + b"\n"  # the first key kept
    assert [p.name for p in tmp_path.iterdir()] == ["site.key"]


def test_a_link_where_a_file_is_made_only_where_none_is_counts_as_a_file(tmp_path: Path) -> None:
    # a link to nowhere at site.key: the key is not written where the link points
    elsewhere = tmp_path / "elsewhere"
    (tmp_path / "site.key").symlink_to(elsewhere)
    with pytest.raises(FileExistsError):
        write_whole(tmp_path / "site.key", b"ab" * 32 + b"\n", exclusive=True)
    assert not elsewhere.exists()


def test_where_files_cannot_be_linked_a_file_is_still_made_only_where_none_is(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a FAT memory stick has no hard links (a fake link call, as nothing here is FAT)
    def no_links(source: object, target: object) -> None:
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr("engine.files.whole_file.os.link", no_links)
    key = tmp_path / "site.key"
    write_whole(key, b"ab" * 32 + b"\n", exclusive=True)
    with pytest.raises(FileExistsError):
        write_whole(key, b"cd" * 32 + b"\n", exclusive=True)
    assert key.read_bytes() == b"ab" * 32 + b"\n"
    assert key.stat().st_mode & 0o777 == 0o600
    assert [p.name for p in tmp_path.iterdir()] == ["site.key"]
