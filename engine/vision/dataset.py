"""A folder of labelled hand pictures, as ``vest gesture record`` and ``generate`` write it.

::

    DATA/0/*.png ... DATA/5/*.png    pictures of a hand showing that many fingers
    DATA/none/*.png                  pictures with no hand (trained towards "not sure")

A picture's session is its file name up to the last ``-`` (``record`` names files
``<session>-<n>.png``): frames of one session look alike, so the held-out pictures are
whole sessions, never random frames of a session the network trained on. Pictures may
be any size at least the window's; training shifts, turns, flips and relights them
(:func:`augment`) before the shared preprocessing.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from engine.errors import ConfigError
from engine.vision.preprocess import (
    LABELS,
    Frame,
    Preprocessing,
    as_input,
    crop,
    edges,
    read_image,
)
from engine.vision.synthetic_hands import NO_HAND

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp")
FOLDERS = (*(str(label) for label in LABELS), NO_HAND)
MARGIN_PX = 24
"""Kept around the window of each training picture: shifts of 8 px and turns of 10
degrees look no further."""
NONE_INDEX = len(LABELS)
"""The label index of a picture with no hand (one past the finger counts)."""


@dataclass(frozen=True)
class Picture:
    """One labelled picture: its file, its label index (0..5, or :data:`NONE_INDEX`) and
    the session it was recorded in."""

    path: Path
    label: int
    session: str


def session_of(path: Path) -> str:
    stem = path.stem
    return stem.rsplit("-", 1)[0] if "-" in stem else stem


def find_pictures(folder: Path) -> list[Picture]:
    """Every labelled picture under ``folder``, sorted by path; ConfigError when the folder
    is missing, holds an unknown label folder, or holds no picture."""
    if not folder.is_dir():
        raise ConfigError(f"{folder}: no such folder (it holds 0/ .. 5/ and none/)")
    unknown = sorted(
        entry.name for entry in folder.iterdir() if entry.is_dir() and entry.name not in FOLDERS
    )
    if unknown:
        raise ConfigError(
            f"{folder / unknown[0]}: not a label folder (they are {', '.join(FOLDERS)})"
        )
    pictures = [
        Picture(path, index, session_of(path))
        for index, name in enumerate(FOLDERS)
        for path in sorted((folder / name).glob("*"))
        if path.suffix.lower() in IMAGE_SUFFIXES
    ]
    if not pictures:
        raise ConfigError(f"{folder}: no pictures in 0/ .. 5/ or none/")
    return pictures


def split(
    pictures: Sequence[Picture], held_out: float, seed: int, *, by: str = "session"
) -> tuple[list[Picture], list[Picture], str]:
    """Pictures to train on and pictures held out (about ``held_out`` of them), whole
    sessions held out when ``by`` is "session" and there are at least two sessions, else
    single pictures; the third value says which split was made."""
    rng = np.random.default_rng(seed)
    sessions = sorted({picture.session for picture in pictures})
    if by == "session" and len(sessions) >= 2:
        order = [sessions[i] for i in rng.permutation(len(sessions))]
        count = min(len(sessions) - 1, max(1, round(len(sessions) * held_out)))
        kept = set(order[:count])
        test = [p for p in pictures if p.session in kept]
        train = [p for p in pictures if p.session not in kept]
        return train, test, f"by session ({count} of {len(sessions)} held out)"
    shuffled = rng.permutation(len(pictures))
    count = min(len(pictures) - 1, max(1, round(len(pictures) * held_out)))
    test_index = set(shuffled[:count].tolist())
    train = [p for i, p in enumerate(pictures) if i not in test_index]
    test = [p for i, p in enumerate(pictures) if i in test_index]
    how = "by picture" if by == "file" else "by picture (only one session)"
    return train, test, how


def load_pictures(pictures: Sequence[Picture], settings: Preprocessing) -> list[Frame]:
    """The pictures' images, each cut to its centred window and a margin of up to
    :data:`MARGIN_PX` around it (all that training's shifts and turns look at: a lab's
    thousands of 640 x 360 frames then fit in memory); ConfigError naming the first that
    cannot be read or is smaller than the window."""
    images = []
    side = settings.side_px
    for picture in pictures:
        try:
            image = read_image(picture.path)
            x, y = settings.window(image.shape[0], image.shape[1])
        except ValueError as error:
            raise ConfigError(
                str(error) if str(picture.path) in str(error) else f"{picture.path}: {error}"
            ) from None
        if settings.crop_x is None and settings.crop_y is None:
            height, width = image.shape[:2]
            margin = min(MARGIN_PX, x, y, width - x - side, height - y - side)
            image = image[y - margin : y + side + margin, x - margin : x + side + margin].copy()
        images.append(image)
    return images


def augment(image: Frame, rng: np.random.Generator, settings: Preprocessing) -> Frame:
    """A window-sized picture made from ``image`` the way a camera might have seen it:
    the window shifted (up to 8 px), turned (up to 10 degrees), scaled (0.9..1.1),
    mirrored half the time, relit and noised."""
    height, width = image.shape[:2]
    x, y = settings.window(height, width)
    side = settings.side_px
    centre = (x + side / 2 + rng.uniform(-8, 8), y + side / 2 + rng.uniform(-8, 8))
    angle, scale = rng.uniform(-10, 10), rng.uniform(0.9, 1.1)
    matrix = cv2.getRotationMatrix2D(centre, angle, scale)
    matrix[:, 2] += np.array([side / 2 - centre[0], side / 2 - centre[1]])
    window = cv2.warpAffine(image, matrix, (side, side), borderMode=cv2.BORDER_REFLECT)
    if rng.random() < 0.5:
        window = window[:, ::-1]
    relit = window.astype(np.float32) * rng.uniform(0.7, 1.3) + rng.uniform(-25, 25)
    relit += rng.normal(0.0, rng.uniform(0.0, 6.0), relit.shape).astype(np.float32)
    return np.asarray(np.clip(relit, 0, 255), dtype=np.uint8)


def network_inputs(windows: Sequence[Frame], settings: Preprocessing) -> npt.NDArray[np.float32]:
    """The edge images of window-sized pictures as a batch (N, 1, side, side) of 0/1
    (:func:`~engine.vision.preprocess.as_input`)."""
    batch = np.empty((len(windows), 1, settings.side_px, settings.side_px), dtype=np.float32)
    for index, window in enumerate(windows):
        batch[index, 0] = as_input(edges(window, settings))
    return batch


def centred_inputs(images: Sequence[Frame], settings: Preprocessing) -> npt.NDArray[np.float32]:
    """The network's inputs for whole pictures: the crop rule, then the preprocessing."""
    return network_inputs([crop(image, settings) for image in images], settings)


def batches(count: int, size: int, rng: np.random.Generator) -> Iterator[npt.NDArray[np.int64]]:
    """Shuffled index batches covering ``count`` items once."""
    order = rng.permutation(count)
    for start in range(0, count, size):
        yield order[start : start + size]
