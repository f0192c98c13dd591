"""The one way vest writes a file whole: whoever reads it sees the old file or the new one,
never a part, and a failure (a full disk, a power cut, a check that refuses the new text)
leaves the old file as it was.

The new bytes go to a temporary file beside the old one, readable by its owner only from
its first byte; they are flushed to the disk, checked (``check``), given their mode, and
the temporary file is renamed over the old one; then the folder is flushed, so the rename
outlives a power cut. The tree editor's saves, consent records and the record of finished
commands are written this way. With ``exclusive`` the whole file is linked into place
only where no file is (the site key: two vests starting at once keep one key, and neither
reads the other's half-written one). (A file a command makes new and streams into is
:func:`engine.cli.output.new_file`'s.)
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

NEW_FILE_MODE = 0o600
"""The mode of a file made new when the caller names none: its owner's alone (what vest
keeps of a session is about children)."""


def write_whole(
    path: Path,
    data: bytes,
    *,
    mode: int | None = None,
    check: Callable[[Path], object] | None = None,
    exclusive: bool = False,
) -> None:
    """``data`` into ``path`` at once (see the module's docstring). ``mode``: the file's
    permission bits (None: the old file's, or :data:`NEW_FILE_MODE` for a new one);
    ``check(temporary)`` reads the new file before it replaces the old and raises to keep
    the old one. OSError (and whatever ``check`` raises) leaves ``path`` untouched and no
    temporary file behind. A link is followed: the file it names is written, the link kept.
    ``exclusive``: FileExistsError when ``path`` is there already (a link too, even one to
    nothing), which is then left as it is (the new file appears whole or not at all)."""
    if path.is_symlink() and not exclusive:  # exclusive: a link there, even dangling, is a file
        path = path.resolve()
    if mode is None:
        mode = path.stat().st_mode & 0o777 if path.exists() else NEW_FILE_MODE
    handle, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    temporary = Path(name)
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
            file.flush()
            os.fsync(file.fileno())
        if check is not None:
            check(temporary)
        os.chmod(temporary, mode)
        if exclusive:
            _link_new(temporary, path, data, mode)
            temporary.unlink()
        else:
            os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    _flush_folder(path.parent)


def _link_new(temporary: Path, path: Path, data: bytes, mode: int) -> None:
    """``temporary`` linked in as ``path``: atomic, and FileExistsError where a file is.
    A file system without hard links (a FAT memory stick) gets ``path`` made with O_EXCL
    and written: still never over another's file, though a reader may then meet it half
    written."""
    try:
        os.link(temporary, path)
    except FileExistsError:
        raise
    except OSError as error:
        if error.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP):
            raise
        descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
        with os.fdopen(descriptor, "wb") as file:
            file.write(data)
            file.flush()
            os.fsync(file.fileno())


def _flush_folder(folder: Path) -> None:
    """The folder's entries to the disk (the rename); where a system cannot open a folder
    for it, the rename is still done."""
    with contextlib.suppress(OSError):
        descriptor = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)
