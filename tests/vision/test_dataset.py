"""A lab's data folder: labelled pictures, held out by session, cut to what training uses."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from engine.errors import ConfigError
from engine.vision.preprocess import Preprocessing
from engine.vision_training.dataset import find_pictures, load_pictures, split


def lab_folder(root: Path) -> Path:
    """Three children's sessions, two counts each, three frames a count."""
    for child in ("anna_1", "ben_1", "cleo_2"):
        for label in ("2", "none"):
            (root / label).mkdir(parents=True, exist_ok=True)
            for frame in range(3):
                picture = np.full((360, 640, 3), 100 + frame, np.uint8)
                cv2.imwrite(str(root / label / f"{child}-{frame:05d}.png"), picture)
    return root


def test_whole_sessions_are_held_out_never_single_frames_of_one(tmp_path: Path) -> None:
    pictures = find_pictures(lab_folder(tmp_path))
    assert len(pictures) == 18
    train, test, how = split(pictures, 0.3, seed=1)
    assert how == "by session (1 of 3 held out)"
    assert {p.session for p in train}.isdisjoint({p.session for p in test})
    assert len(test) == 6


def test_training_keeps_the_window_and_a_margin_not_the_whole_frame(tmp_path: Path) -> None:
    pictures = find_pictures(lab_folder(tmp_path))[:1]
    [image] = load_pictures(pictures, Preprocessing())
    assert image.shape == (128 + 48, 128 + 48, 3)


def test_a_folder_that_is_not_labelled_is_named(tmp_path: Path) -> None:
    (tmp_path / "three").mkdir()
    with pytest.raises(ConfigError, match="three: not a label folder"):
        find_pictures(tmp_path)
    with pytest.raises(ConfigError, match="no pictures in 0/"):
        find_pictures(tmp_path / "three")
