"""The command's own output: standard output that may fail, and text that must not forge lines.

A full disk (``vest run > log`` on a full card) or a reader that went away (``| head``)
makes writing to standard output raise ``OSError``. No command ends in a traceback for it:
``vest run`` keeps the robot going, the other commands say so in one line on stderr.
Text that people wrote (tree names, spoken phrases) is shown with control characters
escaped, so an escape sequence or a newline in a phrase cannot forge a timeline line or
drive the terminal.
"""

from __future__ import annotations

import errno
import os
import stat
import sys
import unicodedata
from pathlib import Path
from typing import Any, TextIO

from engine.errors import ConfigError

# categories whose characters move the cursor, end a line or drive the terminal
_UNSAFE_CATEGORIES = frozenset({"Cc", "Zl", "Zp"})


def shown(text: str) -> str:
    """``text`` with control characters and line separators escaped the way Python's repr
    writes them (``\\x1b``, ``\\n``, ``\\u2028``); other text, accents and every script
    included, is unchanged. Backslashes are kept as written: a human timeline stays
    readable, and a real newline or escape can never come through."""
    if text.isprintable():
        return text  # the common case, without a walk over each character
    return "".join(
        repr(char)[1:-1] if unicodedata.category(char) in _UNSAFE_CATEGORIES else char
        for char in text
    )


def tell(text: str, stream: TextIO | None = None) -> bool:
    """Write one line on ``stream`` (default: standard error); False when it cannot be
    written, which the caller may ignore: nothing else is left to tell the user with."""
    try:
        print(text, file=stream if stream is not None else sys.stderr, flush=True)
    except (OSError, ValueError):  # a full disk, a closed stream
        return False
    return True


class WatchedOutput:
    """A stream (standard output, or its binary buffer) that remembers the first error
    writing to it gave, so a command can tell its own output failing from other errors."""

    def __init__(self, stream: Any) -> None:
        self.stream = stream
        self.error: OSError | None = None
        self._below: WatchedOutput | None = None

    def write(self, data: Any) -> Any:
        try:
            return self.stream.write(data)
        except OSError as error:
            self.error = self.error or error
            raise

    def flush(self) -> None:
        try:
            self.stream.flush()
        except OSError as error:
            self.error = self.error or error
            raise

    @property
    def buffer(self) -> WatchedOutput:
        """The binary stream below, watched the same way (``render --format svg``)."""
        if self._below is None:
            self._below = WatchedOutput(self.stream.buffer)
        return self._below

    @property
    def failed(self) -> OSError | None:
        """The first error writing gave, text or binary."""
        return self.error or (self._below.error if self._below is not None else None)

    def __getattr__(self, name: str) -> Any:  # fileno, isatty, encoding...
        return getattr(self.stream, name)


def discard(stream: TextIO) -> None:
    """Point ``stream``'s file descriptor at /dev/null: what is still buffered goes nowhere,
    so Python's flush at exit does not complain about a stream that already failed."""
    try:
        descriptor = stream.fileno()
    except (AttributeError, OSError, ValueError):  # no descriptor (a test's capture)
        return
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, descriptor)
    finally:
        os.close(null)


def reason(error: OSError) -> str:
    """An OSError in words, without Python's ``[Errno 28]``."""
    return error.strerror or str(error) or type(error).__name__


def writable_folder(folder: Path) -> None:
    """``folder`` exists (made if need be) and a file can be written in it; ConfigError
    naming it when not."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".vest-write-check"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as error:
        raise ConfigError(f"{folder}: cannot write there ({error.strerror or error})") from None


def new_file(path: Path, named_by: str, *, private: bool = False) -> int:
    """A file descriptor of ``path``, made now for writing (O_EXCL: never a file that is
    there, not even one made a moment ago); owner-only when ``private``. ConfigError naming
    it (``named_by``: ``-o out.mcap``) when it is there or cannot be made."""
    try:
        return os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600 if private else 0o644)
    except FileExistsError:
        raise ConfigError(f"{named_by}: is there already; name a new file") from None
    except OSError as error:
        raise ConfigError(f"{named_by}: cannot write it ({reason(error)})") from None


def write_file(path: Path, data: bytes, named_by: str, what: str, *, private: bool = False) -> None:
    """``data`` (``what``: "the report") into the regular file ``path`` (made, or
    replaced); readable by its owner alone when ``private`` (a person's data in the clear).
    ConfigError naming it (``named_by``: as the person did, ``-o r.html``) when it cannot
    be written, or is a folder, a FIFO or a device: opened without blocking, so a FIFO with
    no reader refuses at once instead of hanging the command."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_NONBLOCK | os.O_CLOEXEC
    try:
        descriptor = os.open(path, flags, 0o600 if private else 0o644)
    except OSError as error:
        why = "is not a regular file (a FIFO)" if error.errno == errno.ENXIO else reason(error)
        raise ConfigError(f"{named_by}: cannot write {what} ({why})") from None
    try:
        if not stat.S_ISREG(os.fstat(descriptor).st_mode):
            raise ConfigError(f"{named_by}: cannot write {what} (it is not a regular file)")
        os.set_blocking(descriptor, True)
        if private:
            os.fchmod(descriptor, 0o600)  # a file that was there keeps no wider mode
        os.ftruncate(descriptor, 0)
        view = memoryview(data)
        while view:
            view = view[os.write(descriptor, view) :]
    except OSError as error:
        raise ConfigError(f"{named_by}: cannot write {what} ({reason(error)})") from None
    finally:
        os.close(descriptor)
