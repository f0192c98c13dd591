"""Pictures as vest holds them: a frame is what OpenCV holds, and a picture file is read
by one safe reader that measures it before decoding it."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from engine.files.problems import LoadError
from engine.files.yaml_source import read_bytes
from engine.media.image_size import image_size

Frame = npt.NDArray[np.uint8]
"""An image as OpenCV holds it: rows x columns (x 3 for BGR colour), uint8."""

MAX_IMAGE_BYTES = 64 * 1024 * 1024
MAX_FRAME_PX = 8192
"""The widest or tallest frame or picture vest reads."""


def read_image(path: Path) -> Frame:
    """An image file (PNG, JPEG, BMP, GIF, WebP) as a BGR frame, read by the one safe
    reader and measured from its header before it is decoded: ValueError naming the file
    when it cannot be read, is no picture, or is larger than :data:`MAX_FRAME_PX` a side
    (a small file can hold a huge picture)."""
    try:
        raw = read_bytes(path, max_bytes=MAX_IMAGE_BYTES, kind="picture", too_big_hint="")
    except LoadError as error:
        raise ValueError(f"{path}: {error.problems[0].message}") from None
    size = image_size(raw)
    if size is None:
        raise ValueError(f"{path}: not a picture vest reads (PNG, JPEG, BMP, GIF or WebP)")
    width, height = size
    if not (0 < width <= MAX_FRAME_PX and 0 < height <= MAX_FRAME_PX):
        raise ValueError(
            f"{path}: a {width}x{height} px picture; at most {MAX_FRAME_PX}x{MAX_FRAME_PX}"
        )
    data = np.frombuffer(raw, dtype=np.uint8)
    image = cv2.imdecode(data, cv2.IMREAD_COLOR) if data.size else None
    if image is None:
        raise ValueError(f"{path}: not an image OpenCV can read")
    return np.asarray(image, dtype=np.uint8)
