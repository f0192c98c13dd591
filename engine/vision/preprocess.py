"""How a frame becomes the network's input, written once for training, inference and the
simulated camera. A frame is cropped to a square window without scaling (128 x 128 px; a
picture smaller than the window: its centred square, scaled up to fill it), turned
grayscale, then read one of two ways (``mode``):

- ``edges`` (the paper's, section 4.4, and the shipped model's): blurred (Gaussian,
  3 x 3, sigma 7) and thresholded adaptively (Gaussian weights over an 11 x 11 window) into
  a binary edge image the network reads as 0.0 / 1.0.
- ``gray``: the grayscale window normalised to mean 0 and standard deviation 1, so a hand
  reads the same in a dim room and a bright one. On the photographs of real hands it
  counts less well than edges (docs/vision-model-card.md has both figures); a choice for a
  lab whose light or camera makes edges noisy.

The settings travel beside a model (``model.json`` next to ``model.onnx``), so a model
retrained with other settings carries its own. What the paper leaves open and we chose:
the crop window is centred in the frame; the threshold constant is 4 (grey levels below
the weighted local mean: at 2 a webcam's noise speckles flat areas with edges, at 6 a hand
on a background of nearly its own brightness fades); the network reads edge pixels (black
in the thresholded image) as 1.0 and the rest as 0.0: a sparse input the network learns
from much sooner than the mostly-white image read as it is.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from engine.errors import ConfigError
from engine.files.problems import LoadError
from engine.files.yaml_source import read_bytes
from engine.media.images import MAX_FRAME_PX, Frame

SIDE_PX = 128
LABELS = (0, 1, 2, 3, 4, 5)
"""What the network tells apart: how many fingers a hand shows."""


MODES = ("gray", "edges")
"""How a window is read: normalised grayscale, or the paper's binary edges."""

MAX_SIDE_PX = 1024
MAX_KERNEL_PX = 101
"""The widest blur or threshold window (the paper's are 3 and 11 px)."""
"""The largest window a model may read (the paper's is 128)."""
MAX_SETTINGS_BYTES = 64 * 1024


@dataclass(frozen=True)
class Preprocessing:
    """How a frame becomes the network's input.

    ``crop_x``/``crop_y``: the window's top-left corner in px, or None to centre it;
    ``side_px``: the window's side (the network's input, 128); ``mode``: "gray" or "edges"
    (see the module); for edges, ``blur_px``/``blur_sigma``: the Gaussian blur's kernel
    side (odd) and sigma; ``block_px``: the adaptive threshold's window side (odd);
    ``threshold_c``: subtracted from the weighted local mean (grey levels). A model's
    settings without a mode are the paper's (edges): models made before there was a choice."""

    crop_x: int | None = None
    crop_y: int | None = None
    side_px: int = SIDE_PX
    blur_px: int = 3
    blur_sigma: float = 7.0
    block_px: int = 11
    threshold_c: float = 4.0
    mode: str = "edges"

    def __post_init__(self) -> None:
        """Every number within what a frame can use: a model's settings are a file a person
        may have edited (``blur_px: 99999`` would make one frame take minutes)."""
        if self.mode not in MODES:
            raise ValueError(f"mode must be one of {', '.join(MODES)}, got {self.mode!r}")
        for name in ("side_px", "blur_px", "block_px", "crop_x", "crop_y"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
                raise ValueError(f"{name} must be a whole number of px, got {value!r}")
        for name in ("blur_sigma", "threshold_c"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"{name} must be a number, got {value!r}")
        if not 8 <= self.side_px <= MAX_SIDE_PX:
            raise ValueError(f"side_px must be 8..{MAX_SIDE_PX}, got {self.side_px}")
        for name in ("blur_px", "block_px"):
            value = getattr(self, name)
            if not 1 <= value <= MAX_KERNEL_PX or value % 2 == 0:
                raise ValueError(
                    f"{name} must be a positive odd number of px, at most {MAX_KERNEL_PX}, "
                    f"got {value}"
                )
        if self.block_px < 3:
            raise ValueError(f"block_px must be at least 3, got {self.block_px}")
        if not 0 <= self.blur_sigma <= 100 or not -255 <= self.threshold_c <= 255:
            raise ValueError(
                f"blur_sigma must be 0..100 and threshold_c -255..255, got "
                f"{self.blur_sigma} and {self.threshold_c}"
            )
        for name in ("crop_x", "crop_y"):
            value = getattr(self, name)
            if value is not None and not 0 <= value <= MAX_FRAME_PX:
                raise ValueError(f"{name} must be 0..{MAX_FRAME_PX} px, got {value}")

    def with_crop(self, x: int | None, y: int | None) -> Preprocessing:
        return replace(self, crop_x=x, crop_y=y)

    def window(self, height_px: int, width_px: int) -> tuple[int, int]:
        """The window's top-left corner (x, y) in a frame of this size; ValueError when the
        window does not fit in it."""
        side = self.side_px
        if height_px < side or width_px < side:
            raise ValueError(
                f"a {width_px}x{height_px} image is smaller than the {side}x{side} window"
            )
        x = (width_px - side) // 2 if self.crop_x is None else self.crop_x
        y = (height_px - side) // 2 if self.crop_y is None else self.crop_y
        if x + side > width_px or y + side > height_px:
            raise ValueError(
                f"the {side}x{side} window at x={x}, y={y} does not fit a "
                f"{width_px}x{height_px} image"
            )
        return x, y

    def to_json(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_json(cls, data: Any, where: str) -> Preprocessing:
        """Settings read from a model's JSON; ConfigError naming ``where`` when wrong."""
        if not isinstance(data, dict):
            raise ConfigError(f"{where}: 'preprocessing' must be a mapping")
        known = set(asdict(cls()))
        unknown = sorted(set(data) - known)
        if unknown:
            raise ConfigError(f"{where}: unknown preprocessing field {unknown[0]!r}")
        try:
            return cls(**data)
        except (TypeError, ValueError) as error:
            raise ConfigError(f"{where}: {error}") from None


def fills_window(frame: Frame, settings: Preprocessing) -> bool:
    """Whether ``frame`` is at least the window's size both ways (else :func:`crop` scales
    it up first: a 100 x 100 photograph for a 128 x 128 window)."""
    return bool(min(frame.shape[0], frame.shape[1]) >= settings.side_px)


def filling(frame: Frame, settings: Preprocessing) -> Frame:
    """``frame`` as it is when it fills the window; else the window from it: its centred
    square (its shorter side wide), scaled up to the window's side. A picture smaller than
    the window is no camera frame, so a configured crop position does not apply to it; it
    is cut before it is scaled (an 8192 x 1 px picture costs no more than a square one)."""
    if fills_window(frame, settings):
        return frame
    height, width = frame.shape[:2]
    side = min(height, width)
    top, left = (height - side) // 2, (width - side) // 2
    square = frame[top : top + side, left : left + side]
    size = (settings.side_px, settings.side_px)
    return np.asarray(cv2.resize(square, size, interpolation=cv2.INTER_LINEAR), dtype=np.uint8)


def crop(frame: Frame, settings: Preprocessing) -> Frame:
    """The square window of ``frame`` (no scaling), as a copy; a frame smaller than the
    window is :func:`filling`'s window."""
    if not fills_window(frame, settings):
        return filling(frame, settings)
    x, y = settings.window(frame.shape[0], frame.shape[1])
    side = settings.side_px
    return frame[y : y + side, x : x + side].copy()


def scaled_window(frame: Frame, x: int, y: int, width_px: int, *, side_px: int) -> Frame:
    """The square ``width_px`` wide at (x, y) (px), scaled to ``side_px``: for a picture
    whose hand is not where the paper's crop looks, or bigger than its window. ValueError
    when the square does not fit in ``frame``."""
    height, width = frame.shape[:2]
    if x + width_px > width or y + width_px > height:
        raise ValueError(
            f"the window {width_px}x{width_px} at {x},{y} does not fit a {width}x{height} image"
        )
    square = frame[y : y + width_px, x : x + width_px]
    if width_px == side_px:
        return square.copy()
    scaled = cv2.resize(square, (side_px, side_px), interpolation=cv2.INTER_AREA)
    return np.asarray(scaled, dtype=np.uint8)


def edges(window: Frame, settings: Preprocessing) -> Frame:
    """Grayscale, blurred, adaptively thresholded: a binary image, 0 or 255 (uint8)."""
    gray = cv2.cvtColor(window, cv2.COLOR_BGR2GRAY) if window.ndim == 3 else window
    blurred = cv2.GaussianBlur(gray, (settings.blur_px, settings.blur_px), settings.blur_sigma)
    binary = cv2.adaptiveThreshold(
        blurred,
        255,
        cv2.ADAPTIVE_THRESH_GAUSSIAN_C,
        cv2.THRESH_BINARY,
        settings.block_px,
        settings.threshold_c,
    )
    return np.asarray(binary, dtype=np.uint8)


def as_input(binary: Frame) -> npt.NDArray[np.float32]:
    """A thresholded window as the network reads it: 1.0 on edges (black, 0), else 0.0."""
    result: npt.NDArray[np.float32] = (binary == 0).astype(np.float32)
    return result


def normalised_gray(window: Frame) -> npt.NDArray[np.float32]:
    """The window in grayscale with mean 0 and standard deviation 1 (a flat window: 0)."""
    gray = cv2.cvtColor(window, cv2.COLOR_BGR2GRAY) if window.ndim == 3 else window
    values = gray.astype(np.float32)
    spread = float(values.std())
    result: npt.NDArray[np.float32] = (values - float(values.mean())) / max(spread, 1.0)
    return result


def window_input(window: Frame, settings: Preprocessing) -> npt.NDArray[np.float32]:
    """A window-sized picture as the network reads it, (side, side) float32, by the
    settings' ``mode``."""
    if settings.mode == "gray":
        return normalised_gray(window)
    return as_input(edges(window, settings))


def network_input(frame: Frame, settings: Preprocessing) -> npt.NDArray[np.float32]:
    """What the network reads for ``frame``: its window (:func:`crop`) read by the
    settings' mode, shape (1, side, side)."""
    return window_input(crop(frame, settings), settings)[np.newaxis]


def load_settings(path: Path) -> dict[str, Any]:
    """A model's JSON sidecar as a mapping, read by the one safe reader (a FIFO or a huge
    file is refused, never waited on); ConfigError naming the file when unreadable."""
    if not path.exists():
        raise ConfigError(f"{path}: no such file (a model's settings sit beside it)")
    try:
        raw = read_bytes(
            path,
            max_bytes=MAX_SETTINGS_BYTES,
            kind="model settings file",
            too_big_hint="a model's settings are a few lines of JSON",
        )
        data = json.loads(raw.decode("utf-8"))
    except LoadError as error:
        raise ConfigError(str(error.problems[0])) from None
    except (ValueError, RecursionError) as error:  # bad UTF-8, bad JSON, a 5,000-digit number
        raise ConfigError(f"{path}: not readable JSON ({error})") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: must hold a JSON object")
    return data
