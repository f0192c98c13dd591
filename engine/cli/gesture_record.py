"""``vest gesture record``: labelled pictures into a data folder, for training on a lab's
own hands.

From the camera, either ``--label N --frames K`` (K frames in a row, a few frames apart
so they are not all the same) or, without ``--label``, one frame each time a label is
typed (``0``..``5``, ``n`` for no hand, then Enter; ``q`` or end of input stops). From a
folder with ``--from``: every picture in it (of the ``--label`` count, or in its own
``0/`` .. ``5/`` and ``none/`` folders), checked and stored as PNG. Files are named
``<session>-<n>.png``: training holds whole sessions out, so record each child or each
sitting as its own session (``--session``, by default the date and time).
"""

from __future__ import annotations

import argparse
import datetime
import re
import sys
from pathlib import Path

import cv2

from engine.cli.output import writable_folder
from engine.clock import EpochClock
from engine.errors import ConfigError
from engine.media.camera import CameraError, OpenCvCamera
from engine.media.images import Frame, read_image
from engine.vision_training.dataset import FOLDERS, IMAGE_SUFFIXES
from engine.vision_training.synthetic_hands import NO_HAND

SESSION = re.compile(r"[A-Za-z0-9_.]+")
FRAMES_APART = 3
"""In a burst, frames skipped between two kept (at 15 fps, five pictures a second)."""
KEYS = {**{str(n): str(n) for n in range(6)}, "n": NO_HAND, "none": NO_HAND}


def record(args: argparse.Namespace) -> int:
    now = datetime.datetime.fromtimestamp(EpochClock().now())
    session = args.session or now.strftime("%Y%m%d_%H%M%S")
    if not SESSION.fullmatch(session):
        raise ConfigError(
            f"--session {session!r}: use letters, digits, '_' and '.' (no '-': it ends a session)"
        )
    if args.source is not None:
        return _from_folder(args.data, args.source, args.label, session)
    if args.frames is not None and args.label is None:
        raise ConfigError("--frames needs --label (without it, type a label per frame)")
    writable_folder(args.data)
    camera = OpenCvCamera(int(args.camera) if args.camera.isdigit() else args.camera)
    camera.open()
    try:
        if args.label is not None:
            return _burst(camera, args.data, args.label, session, args.frames or 50)
        return _by_key(camera, args.data, session)
    finally:
        camera.close()


class Recorder:
    """Writes ``DATA/<label>/<session>-<n>.png``, numbering after what is already there."""

    def __init__(self, data: Path, session: str) -> None:
        self.data, self.session = data, session
        self.saved = 0

    def save(self, frame: Frame, label: str) -> Path:
        folder = self.data / label
        writable_folder(folder)
        number = len(list(folder.glob(f"{self.session}-*.png")))
        path = folder / f"{self.session}-{number:05d}.png"
        while path.exists():
            number += 1
            path = folder / f"{self.session}-{number:05d}.png"
        if not cv2.imwrite(str(path), frame):
            raise ConfigError(f"{path}: cannot be written")
        self.saved += 1
        return path


def _burst(camera: OpenCvCamera, data: Path, label: str, session: str, frames: int) -> int:
    recorder = Recorder(data, session)
    read = 0
    while recorder.saved < frames:
        try:
            frame = camera.read()
        except CameraError as error:
            if recorder.saved == 0:
                raise
            print(f"{camera.name} stopped after {recorder.saved} frames: {error}")
            break
        if read % FRAMES_APART == 0:
            recorder.save(frame, label)
        read += 1
    print(f"{recorder.saved} pictures of {label} in {data / label} (session {session})")
    return 0


def _by_key(camera: OpenCvCamera, data: Path, session: str) -> int:
    recorder = Recorder(data, session)
    print("type a label and Enter to keep the newest frame: 0..5, n (no hand); q stops")
    for line in sys.stdin:
        key = line.strip().lower()
        if key in ("q", "quit"):
            break
        if key not in KEYS:
            print(f"{key!r}: not a label (0..5, n, or q)")
            continue
        try:
            frame = camera.newest()
        except CameraError as error:
            print(f"{error}; kept {recorder.saved} pictures")
            return 1
        print(f"kept {recorder.save(frame, KEYS[key])}")
    print(f"{recorder.saved} pictures in {data} (session {session})")
    return 0


def _from_folder(data: Path, source: Path, label: str | None, session: str) -> int:
    """Pictures of one count from a folder (``--label``), or a folder laid out as a data
    folder is (``0/`` .. ``5/``, ``none/``) without it."""
    if not source.is_dir():
        raise ConfigError(f"{source}: no such folder")
    if label is None:
        labelled = [(source / name, name) for name in FOLDERS if (source / name).is_dir()]
        if not labelled:
            raise ConfigError(
                f"{source}: holds no 0/ .. 5/ or none/ folders; name the count of its "
                "pictures with --label"
            )
    else:
        labelled = [(source, label)]
    recorder = Recorder(data, session)
    skipped = 0
    for folder, name in labelled:
        for path in sorted(folder.iterdir()):
            if path.suffix.lower() not in IMAGE_SUFFIXES:
                continue
            try:
                recorder.save(read_image(path), name)
            except ValueError as error:  # ConfigError is one too
                print(f"skipped {path}: {error}")
                skipped += 1
    if recorder.saved == 0:
        raise ConfigError(f"{source}: no picture that could be used")
    counts = ", ".join(name for _, name in labelled)
    print(
        f"{recorder.saved} pictures ({counts}) in {data}"
        + (f"; {skipped} skipped" if skipped else "")
    )
    return 0
