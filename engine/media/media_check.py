"""Pictures and videos a person names (a scenario's ``show_hand``): checked before a run."""

from __future__ import annotations

from pathlib import Path

import cv2

from engine.media.images import MAX_FRAME_PX, read_image


def check_media(path: Path, *, video: bool) -> str | None:
    """Why ``path`` cannot be shown to the camera (a picture, or a video when ``video``),
    or None when it can: the file is there and OpenCV reads a frame of it."""
    if not path.exists():
        return f"{path}: no such file"
    if not path.is_file():  # a folder, a FIFO (OpenCV would wait on it), a device
        return f"{path}: is not a regular file; name a {'video' if video else 'picture'} file"
    if not video:
        try:
            read_image(path)
        except ValueError as error:
            return str(error)
        return None
    capture = cv2.VideoCapture(str(path))
    try:
        if not capture.isOpened():
            return f"{path}: not a video OpenCV can play"
        width = int(capture.get(cv2.CAP_PROP_FRAME_WIDTH))
        height = int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT))
        if not (0 < width <= MAX_FRAME_PX and 0 < height <= MAX_FRAME_PX):
            return f"{path}: {width}x{height} px frames; at most {MAX_FRAME_PX}x{MAX_FRAME_PX}"
        ok = capture.read()[0]
    finally:
        capture.release()
    return None if ok else f"{path}: not a video OpenCV can play"
