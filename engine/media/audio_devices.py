"""The microphone and the speaker as ALSA devices, through the ``arecord`` and ``aplay``
programs (alsa-utils): 16-bit mono PCM on a pipe, no compiled binding to build.

A device that cannot be opened (no sound card, a wrong name) raises
:class:`AudioDeviceError` naming it and why, so the robot reports it like a chip that
does not answer and runs on without speech.
"""

from __future__ import annotations

import logging
import queue
import shutil
import subprocess
import threading
from collections.abc import Callable
from dataclasses import dataclass

from engine.errors import DeviceError
from engine.media.audio import SPEECH_RATE_HZ, Audio

log = logging.getLogger(__name__)
CAPTURE_CHUNK_S = 0.064
"""The microphone hands over audio in pieces this long (two VAD frames)."""


class AudioDeviceError(DeviceError):
    """A sound device that cannot be used, in words: which one and why."""


@dataclass(frozen=True)
class AudioDeviceStatus:
    """One sound device for ``vest devices``: its role, ALSA name, and whether it works."""

    role: str
    device: str
    ok: bool
    detail: str


def _tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        raise AudioDeviceError(f"{name} is not installed (Debian package alsa-utils)")
    return path


def _start(command: list[str], role: str, device: str) -> subprocess.Popen[bytes]:
    """Start ``command``; AudioDeviceError when it fails at once (no such card)."""
    try:
        process = subprocess.Popen(
            command,
            stdin=subprocess.PIPE if role == "speaker" else subprocess.DEVNULL,
            stdout=subprocess.PIPE if role == "microphone" else subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
    except OSError as error:
        raise AudioDeviceError(f"{role} {device!r}: {error.strerror or error}") from None
    try:
        process.wait(timeout=0.2)
    except subprocess.TimeoutExpired:
        return process  # still running: the device opened
    why = (process.stderr.read().decode(errors="replace") if process.stderr else "").strip()
    raise AudioDeviceError(
        f"{role} {device!r} cannot be opened: {_first_line(why)} (`vest devices` lists the "
        "sound devices; name one with --device or in the robot config)"
    )


def _first_line(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    return lines[-1].strip() if lines else "it exited at once"


def probe(role: str, device: str) -> AudioDeviceStatus:
    """Open the device for a moment: is it there?"""
    tool = "arecord" if role == "microphone" else "aplay"
    try:
        command = [
            _tool(tool),
            "-q",
            "-D",
            device,
            "-t",
            "raw",
            "-f",
            "S16_LE",
            "-c",
            "1",
            "-r",
            str(SPEECH_RATE_HZ),
        ]
        if role == "microphone":
            command += ["-d", "1"]
        process = _start(command, role, device)
        process.kill()
        process.wait()
    except AudioDeviceError as error:
        return AudioDeviceStatus(role, device, False, str(error))
    return AudioDeviceStatus(role, device, True, f"opened with {tool}")


class AlsaSpeaker:
    """Plays audio on an ALSA device. ``start`` queues audio behind what is playing and
    returns at once (one writer thread feeds ``aplay``, in order); ``stop`` silences it now."""

    def __init__(self, device: str = "default") -> None:
        self.device = device
        self._process: subprocess.Popen[bytes] | None = None
        self._rate_hz = 0
        self._lock = threading.Lock()
        self._pieces: queue.Queue[tuple[subprocess.Popen[bytes], bytes] | None] = queue.Queue()
        self._writer: threading.Thread | None = None

    def _open(self, rate_hz: int) -> subprocess.Popen[bytes]:
        if self._process is not None and self._process.poll() is None and rate_hz == self._rate_hz:
            return self._process
        self._close()
        command = [
            _tool("aplay"),
            "-q",
            "-D",
            self.device,
            "-t",
            "raw",
            "-f",
            "S16_LE",
            "-c",
            "1",
            "-r",
            str(rate_hz),
        ]
        self._process = _start(command, "speaker", self.device)
        self._rate_hz = rate_hz
        return self._process

    def open(self, rate_hz: int) -> None:
        """Open the device now; AudioDeviceError naming it when it cannot be."""
        with self._lock:
            self._open(rate_hz)

    def start(self, audio: Audio, at_s: float) -> None:
        """Queue ``audio`` behind what is playing (``at_s`` is the speaker's own reckoning)."""
        with self._lock:
            process = self._open(audio.rate_hz)
            if self._writer is None:
                self._writer = threading.Thread(target=self._write, name="speaker", daemon=True)
                self._writer.start()
        self._pieces.put((process, audio.pcm16()))

    def _write(self) -> None:
        while (piece := self._pieces.get()) is not None:
            process, data = piece
            try:
                if process.stdin is not None and process.poll() is None:
                    process.stdin.write(data)
                    process.stdin.flush()
            except (BrokenPipeError, ValueError, OSError):
                pass  # stopped while writing: the next piece goes to the new process

    def stop(self, at_s: float | None = None) -> None:
        """Silence now (``at_s``, when the robot decided to, is past for a sound card)."""
        with self._lock:
            self._close()

    def _close(self) -> None:
        if self._process is not None:
            self._process.kill()
            self._process.wait()
            self._process = None

    def close(self) -> None:
        self.stop()
        if self._writer is not None:
            self._pieces.put(None)
            self._writer.join(timeout=2.0)
            self._writer = None


class AlsaMicrophone:
    """Captures 16 kHz mono from an ALSA device in a thread and hands each piece to
    ``on_audio``. ``start`` raises AudioDeviceError when the device cannot be opened."""

    def __init__(self, device: str, on_audio: Callable[[Audio], None]) -> None:
        self.device = device
        self.on_audio = on_audio
        self._process: subprocess.Popen[bytes] | None = None
        self._thread: threading.Thread | None = None
        self.error: str | None = None
        """Why capture stopped, when it stopped by itself (the card went away)."""

    def start(self) -> None:
        command = [
            _tool("arecord"),
            "-q",
            "-D",
            self.device,
            "-t",
            "raw",
            "-f",
            "S16_LE",
            "-c",
            "1",
            "-r",
            str(SPEECH_RATE_HZ),
        ]
        self._process = _start(command, "microphone", self.device)
        self._thread = threading.Thread(target=self._read, name="microphone", daemon=True)
        self._thread.start()

    def _read(self) -> None:
        process = self._process
        assert process is not None and process.stdout is not None
        chunk = int(CAPTURE_CHUNK_S * SPEECH_RATE_HZ) * 2
        while True:
            data = process.stdout.read(chunk)
            if not data:
                break
            self.on_audio(Audio.from_pcm16(data, SPEECH_RATE_HZ))
        if process.wait() != -9:  # not closed by us: the card went away
            why = process.stderr.read().decode(errors="replace") if process.stderr else ""
            self.error = f"microphone {self.device!r} stopped: {_first_line(why)}"
            log.warning("%s; the robot no longer hears", self.error)

    def close(self) -> None:
        if self._process is not None:
            self._process.kill()
            self._process.wait()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
