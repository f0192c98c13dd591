"""The preprocessing, shared by training, the robot and the simulated camera: a window
cut without scaling (a smaller picture scaled up to fill it), then the paper's grayscale,
blur, adaptive threshold and edges read as 1, or normalised grayscale."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from engine.errors import ConfigError
from engine.media.images import read_image
from engine.vision.preprocess import (
    Preprocessing,
    as_input,
    crop,
    edges,
    network_input,
    scaled_window,
)


def numbered_frame(height: int, width: int) -> np.ndarray:
    """A grey frame whose pixel (row, column) holds row * 10 + column: a crop shows where
    it was taken from."""
    rows, columns = np.mgrid[0:height, 0:width]
    return (rows * 10 + columns).astype(np.uint8)


def test_the_window_is_cut_from_the_middle_without_scaling() -> None:
    frame = numbered_frame(8, 10)  # 10 wide, 8 high; an 8 px window starts at x=1, y=0
    window = crop(frame, Preprocessing(side_px=8))
    assert window.shape == (8, 8)
    assert window[0, 0] == 1 and window[7, 7] == 78  # row 0 col 1 .. row 7 col 8


def test_a_configured_window_is_cut_where_it_is_asked() -> None:
    window = crop(numbered_frame(12, 12), Preprocessing(side_px=8, crop_x=3, crop_y=2))
    assert window[0, 0] == 23 and window[7, 7] == 100


def test_the_paper_frame_gives_the_window_at_256_116() -> None:
    assert Preprocessing().window(360, 640) == (256, 116)


def test_a_window_that_does_not_fit_is_refused_with_both_sizes() -> None:
    with pytest.raises(ValueError, match=r"a 100x90 image is smaller than the 128x128 window"):
        Preprocessing().window(90, 100)
    with pytest.raises(ValueError, match=r"at x=600, y=0 does not fit a 640x360"):
        Preprocessing(crop_x=600, crop_y=0).window(360, 640)


def test_a_flat_picture_has_no_edges() -> None:
    flat = np.full((16, 16), 120, np.uint8)
    assert (edges(flat, Preprocessing(side_px=16)) == 255).all()
    assert as_input(edges(flat, Preprocessing(side_px=16))).sum() == 0


def test_a_step_from_dark_to_light_is_an_edge_on_its_dark_side_only() -> None:
    """Left half 20, right half 220. A dark pixel next to the step sees a local mean well
    above its own value (edge, 0); a light pixel sees a mean below its own (255); pixels
    more than half the 11 px window (plus the 3 px blur) away see only their own side."""
    step = np.full((24, 24), 20, np.uint8)
    step[:, 12:] = 220
    binary = edges(step, Preprocessing(side_px=24))
    row = binary[12]
    assert row[11] == 0 and row[10] == 0  # just left of the step: edge
    assert (row[12:] == 255).all()  # the light side: never an edge
    assert (row[:5] == 255).all()  # far on the dark side: its window is all dark
    assert set(np.unique(binary)) <= {0, 255}


def test_the_network_reads_edges_as_one_and_the_rest_as_zero() -> None:
    frame = np.full((360, 640, 3), 200, np.uint8)
    frame[150:250, 300:340] = 30  # a dark bar in the window
    inputs = network_input(frame, Preprocessing())
    assert inputs.shape == (1, 128, 128) and inputs.dtype == np.float32
    assert set(np.unique(inputs)) == {0.0, 1.0}
    # the bar's left edge is at column 300 - 256 = 44 of the window, rows 34..133
    assert inputs[0, 60, 44] == 1.0 and inputs[0, 60, 20] == 0.0


def test_a_colour_frame_reads_as_its_grey_levels() -> None:
    grey = np.random.default_rng(3).integers(0, 256, (128, 128), dtype=np.uint8)
    colour = np.repeat(grey[..., np.newaxis], 3, axis=2)
    np.testing.assert_array_equal(
        network_input(colour, Preprocessing()), network_input(grey, Preprocessing())
    )


def test_a_bigger_window_is_scaled_down_to_the_network_size() -> None:
    frame = np.zeros((300, 300, 3), np.uint8)
    frame[:, 150:] = 255
    window = scaled_window(frame, 22, 22, 256, side_px=128)
    assert window.shape == (128, 128, 3)
    assert window[0, 0, 0] == 0 and window[0, 127, 0] == 255
    with pytest.raises(ValueError, match="does not fit a 300x300 image"):
        scaled_window(frame, 100, 100, 256, side_px=128)


def test_settings_travel_as_json_and_a_wrong_field_is_named() -> None:
    settings = Preprocessing(crop_x=10, crop_y=20, threshold_c=3.0)
    assert Preprocessing.from_json(json.loads(json.dumps(settings.to_json())), "m.json") == settings
    with pytest.raises(ConfigError, match=r"m\.json: unknown preprocessing field 'blur'"):
        Preprocessing.from_json({"blur": 3}, "m.json")
    with pytest.raises(ConfigError, match=r"m\.json: block_px must be a positive odd number"):
        Preprocessing.from_json({"block_px": 10}, "m.json")


def test_a_file_that_is_not_a_picture_is_named(tmp_path: Path) -> None:
    text = tmp_path / "notes.png"
    text.write_text("not a picture")
    with pytest.raises(ValueError, match=r"notes\.png: not a picture vest reads"):
        read_image(text)
    with pytest.raises(ValueError, match=r"missing\.png: file not found"):
        read_image(tmp_path / "missing.png")


def test_gray_reads_the_window_normalised_whatever_the_light() -> None:
    rng = np.random.default_rng(3)
    scene = rng.integers(0, 200, size=(128, 128, 3)).astype(np.float32)
    dim, bright = (scene * 0.4).astype(np.uint8), np.clip(scene * 1.2 + 20, 0, 255).astype(np.uint8)
    gray = Preprocessing(mode="gray")
    read_dim, read_bright = network_input(dim, gray), network_input(bright, gray)
    assert read_dim.shape == (1, 128, 128)
    assert abs(float(read_dim.mean())) < 1e-4 and abs(float(read_dim.std()) - 1.0) < 1e-3
    np.testing.assert_allclose(read_dim, read_bright, atol=0.1)  # the same scene, relit
    flat = np.full((128, 128, 3), 90, np.uint8)
    assert not network_input(flat, gray).any()  # nothing to see: zeros, never a division by 0


def test_settings_without_a_mode_are_the_papers_and_an_unknown_mode_is_named() -> None:
    assert Preprocessing.from_json({"blur_px": 3}, "old.json").mode == "edges"
    with pytest.raises(ConfigError, match=r"old\.json: mode must be one of gray, edges"):
        Preprocessing.from_json({"mode": "color"}, "old.json")


def test_a_picture_smaller_than_the_window_is_scaled_up_to_fill_it() -> None:
    photo = np.zeros((100, 80, 3), np.uint8)
    photo[:, :40] = 200  # the left half bright
    window = crop(photo, Preprocessing())
    assert window.shape == (128, 128, 3)  # its centred 80 x 80 square, scaled to 128
    assert window[:, :60].min() == 200 and window[:, 68:].max() == 0
    placed = Preprocessing(crop_x=300, crop_y=100)  # a camera's window: not for a photograph
    assert np.array_equal(crop(photo, placed), window)


def test_a_picture_of_absurd_shape_is_cut_before_it_is_scaled() -> None:
    """An 8192 x 1 px strip would become 1,048,576 x 128 px if scaled whole."""
    strip = np.full((1, 8192, 3), 77, np.uint8)
    assert crop(strip, Preprocessing()).shape == (128, 128, 3)
    assert network_input(strip, Preprocessing()).shape == (1, 128, 128)


def test_the_command_line_offers_every_preprocessing_mode_and_no_other() -> None:
    """`vest gesture train --preprocess` lists the modes without loading OpenCV."""
    from engine.cli.gesture_command import PREPROCESS_MODES
    from engine.vision.preprocess import MODES

    assert sorted(PREPROCESS_MODES) == sorted(MODES)
