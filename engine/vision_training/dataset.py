"""A folder of labelled hand pictures, as ``vest gesture record`` and ``generate`` write it.

::

    DATA/0/*.png ... DATA/5/*.png    pictures of a hand showing that many fingers
    DATA/none/*.png                  pictures with no hand (trained towards "not sure")

A picture's session is its file name up to the last ``-`` (``record`` names files
``<session>-<n>.png``): frames of one session look alike, so the held-out pictures are
whole sessions, never random frames of a session the network trained on. Pictures may
be any size (one smaller than the window is scaled up to fill it); training shifts, turns,
flips and relights them (:func:`augment`) before the shared preprocessing.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from engine.errors import ConfigError
from engine.media.images import Frame, read_image
from engine.vision.preprocess import (
    LABELS,
    Preprocessing,
    crop,
    filling,
    fills_window,
    window_input,
)
from engine.vision_training.synthetic_hands import NO_HAND

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
    thousands of 640 x 360 frames then fit in memory; a picture smaller than the window is
    scaled up to fill it first); ConfigError naming the first that cannot be read."""
    images = []
    side = settings.side_px
    for picture in pictures:
        try:
            image = read_image(picture.path)
            if not fills_window(image, settings):  # a small one: its window, scaled up
                images.append(filling(image, settings))
                continue
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
    """A window-sized picture made from ``image`` the way another camera, room or child
    might have shown it: the window shifted (up to 10 px), turned (up to 20 degrees),
    scaled (0.8..1.15), mirrored half the time; each colour channel gained on its own
    (0.6..1.4: skin tones, white balance), brightened or darkened, gamma-curved
    (0.7..1.4), sometimes blurred (out of focus), and noised."""
    height, width = image.shape[:2]
    side = settings.side_px
    # a window-sized picture (a small one, scaled up when loaded) is its own window
    x, y = (0, 0) if (height, width) == (side, side) else settings.window(height, width)
    centre = (x + side / 2 + rng.uniform(-10, 10), y + side / 2 + rng.uniform(-10, 10))
    angle, scale = rng.uniform(-20, 20), rng.uniform(0.8, 1.15)
    matrix = cv2.getRotationMatrix2D(centre, angle, scale)
    matrix[:, 2] += np.array([side / 2 - centre[0], side / 2 - centre[1]])
    window = cv2.warpAffine(image, matrix, (side, side), borderMode=cv2.BORDER_REPLICATE)
    if rng.random() < 0.5:
        window = window[:, ::-1]
    relit = window.astype(np.float32)
    if relit.ndim == 3:
        relit *= rng.uniform(0.6, 1.4, size=relit.shape[2]).astype(np.float32)
    relit += rng.uniform(-30, 30)
    if rng.random() < 0.3:
        relit = np.asarray(cv2.GaussianBlur(relit, (5, 5), rng.uniform(0.1, 1.5)), np.float32)
    relit += np.asarray(rng.normal(0.0, rng.uniform(0.0, 8.0), size=relit.shape), np.float32)
    curved = 255.0 * (np.clip(relit, 0, 255) / 255.0) ** rng.uniform(0.7, 1.4)
    return np.asarray(np.clip(curved, 0, 255), dtype=np.uint8)


def network_inputs(windows: Sequence[Frame], settings: Preprocessing) -> npt.NDArray[np.float32]:
    """Window-sized pictures as the network reads them, a batch (N, 1, side, side)
    (:func:`~engine.vision.preprocess.window_input`)."""
    batch = np.empty((len(windows), 1, settings.side_px, settings.side_px), dtype=np.float32)
    for index, window in enumerate(windows):
        batch[index, 0] = window_input(window, settings)
    return batch


def centred_inputs(images: Sequence[Frame], settings: Preprocessing) -> npt.NDArray[np.float32]:
    """The network's inputs for whole pictures: the crop rule, then the preprocessing."""
    return network_inputs([crop(image, settings) for image in images], settings)


def batches(count: int, size: int, rng: np.random.Generator) -> Iterator[npt.NDArray[np.int64]]:
    """Shuffled index batches covering ``count`` items once."""
    order = rng.permutation(count)
    for start in range(0, count, size):
        yield order[start : start + size]
