"""The hand the simulated camera sees when a scenario says ``show_hand: {fingers: N}``."""

from __future__ import annotations

import numpy as np

from engine.media.images import Frame
from engine.vision.preprocess import SIDE_PX
from engine.vision_training.synthetic_hands import HandPose, Random, draw_hand


def render_shown_hand(
    fingers: int,
    rng: Random,
    *,
    width_px: int = 640,
    height_px: int = 360,
    window: tuple[int, int] | None = None,
) -> Frame:
    """A hand held up to the robot on purpose (the simulated camera's ``show_hand``):
    facing it, upright, in the middle of the crop window, the first fingers up, in a calm
    room; drawn by the studio code, with its skin tones and light."""
    x, y = window if window is not None else ((width_px - SIDE_PX) // 2, (height_px - SIDE_PX) // 2)
    base = rng.integers(60, 230, size=3).astype(float)
    shade = np.linspace(rng.uniform(0.85, 1.0), rng.uniform(1.0, 1.15), width_px, dtype=np.float32)
    frame = np.asarray(np.clip(base * shade[np.newaxis, :, np.newaxis], 0, 255), dtype=np.uint8)
    frame = np.ascontiguousarray(np.broadcast_to(frame, (height_px, width_px, 3)))
    common = [1, 2, 3, 4, 0][:fingers]
    pose = HandPose(
        centre=(
            SIDE_PX / 2 + float(rng.normal(0.0, 3.0)),
            SIDE_PX / 2 + 15 + float(rng.normal(0.0, 3.0)),
        ),
        palm_px=float(rng.uniform(21.0, 25.0)),
        angle_deg=float(rng.normal(0.0, 5.0)),
        mirrored=bool(rng.random() < 0.5),
        extended=tuple(digit in common for digit in range(5)),
    )
    draw_hand(frame[y : y + SIDE_PX, x : x + SIDE_PX], pose, rng, style="studio")
    noisy = frame.astype(np.float32) + rng.normal(0.0, 2.0, frame.shape).astype(np.float32)
    return np.asarray(np.clip(noisy, 0, 255), dtype=np.uint8)
