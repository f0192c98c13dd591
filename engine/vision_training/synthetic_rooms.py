"""The rooms the drawn hands are held up in: backgrounds and what a webcam adds.

Part of the hand generator (:mod:`engine.vision_training.synthetic_hands`): ``studio`` rooms are
plain, graded or cluttered; ``wallpaper`` walls are busy patterns (plaids, dots, bricks,
grain); ``variant`` walls, never trained on, are striped, checked or smoothly textured.
"""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from engine.media.images import Frame

Random = np.random.Generator


def background(height: int, width: int, rng: Random, style: str) -> Frame:
    """A background: plain, graded or cluttered (studio); striped, checked or textured
    (variant)."""
    base = rng.integers(0, 256, size=3).astype(float)
    other = rng.integers(0, 256, size=3).astype(float)
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float32)
    if style == "varied":
        style = "studio" if rng.random() < 0.5 else "wallpaper"
    if style == "wallpaper":
        return wallpaper(xs, ys, base, other, rng)
    if style == "studio":
        angle = rng.uniform(0, 2 * np.pi)
        ramp = (np.cos(angle) * xs + np.sin(angle) * ys) / max(height, width)
        ramp = (ramp - ramp.min()) / (np.ptp(ramp) or 1.0) * rng.uniform(0.0, 1.0)
        image = base + (other - base) * ramp[..., np.newaxis]
        image = np.clip(image, 0, 255).astype(np.uint8)
        busy = rng.random() < 0.35  # a cluttered room: many small things, many edges
        reach = max(6, (height + width) // (16 if busy else 6))
        for _ in range(int(rng.integers(15, 40)) if busy else int(rng.integers(0, 7))):
            colour = tuple(int(c) for c in rng.integers(0, 256, 3))
            centre = (int(rng.integers(0, width)), int(rng.integers(0, height)))
            if rng.random() < 0.5:
                axes = (int(rng.integers(3, reach)), int(rng.integers(3, reach)))
                cv2.ellipse(
                    image, centre, axes, float(rng.uniform(0, 180)), 0, 360, colour, -1, cv2.LINE_AA
                )
            elif rng.random() < 0.5:
                corner = (
                    centre[0] + int(rng.integers(5, reach * 3 // 2)),
                    centre[1] + int(rng.integers(5, reach * 3 // 2)),
                )
                cv2.rectangle(image, centre, corner, colour, -1)
            else:
                end = (int(rng.integers(0, width)), int(rng.integers(0, height)))
                cv2.line(image, centre, end, colour, int(rng.integers(1, 4)), cv2.LINE_AA)
        return np.asarray(image, dtype=np.uint8)
    kind = rng.integers(3)
    if kind == 0:  # stripes at any angle
        angle = rng.uniform(0, np.pi)
        period = rng.uniform(6.0, 30.0)
        phase = (np.cos(angle) * xs + np.sin(angle) * ys) / period
        mix = (
            (np.sin(2 * np.pi * phase) > 0).astype(np.float32)
            if rng.random() < 0.5
            else 0.5 + 0.5 * np.sin(2 * np.pi * phase)
        )
    elif kind == 1:  # a checkerboard
        cell = rng.uniform(6.0, 24.0)
        mix = ((xs // cell + ys // cell) % 2).astype(np.float32)
    else:  # a texture: smooth noise upscaled
        coarse = rng.random((int(rng.integers(3, 12)), int(rng.integers(3, 12)))).astype(np.float32)
        mix = cv2.resize(coarse, (width, height), interpolation=cv2.INTER_CUBIC)
        mix = np.clip(mix, 0.0, 1.0) + rng.normal(0.0, 0.08, (height, width)).astype(np.float32)
    image = base + (other - base) * np.clip(mix, 0.0, 1.0)[..., np.newaxis]
    return np.asarray(np.clip(image, 0, 255), dtype=np.uint8)


def wallpaper(
    xs: npt.NDArray[np.float32],
    ys: npt.NDArray[np.float32],
    base: npt.NDArray[np.float64],
    other: npt.NDArray[np.float64],
    rng: Random,
) -> Frame:
    """A busy patterned wall (the wallpaper style): a plaid of crossing waves, a grid of
    dots, bricks, or grain; many edges the network must learn to look past."""
    kind = rng.integers(4)
    if kind == 0:  # plaid: two or three waves at any angles and periods
        mix = np.zeros_like(xs)
        for _ in range(int(rng.integers(2, 4))):
            angle, period = rng.uniform(0, np.pi), rng.uniform(5.0, 28.0)
            mix += np.sin(2 * np.pi * (np.cos(angle) * xs + np.sin(angle) * ys) / period)
        if rng.random() < 0.5:
            mix = (mix > rng.uniform(-0.5, 0.5)).astype(np.float32)
        mix = ((mix - mix.min()) / (np.ptp(mix) or 1.0)).astype(np.float32)
    elif kind == 1:  # dots on a grid
        spacing = rng.uniform(7.0, 22.0)
        radius = spacing * rng.uniform(0.15, 0.4)
        gx = (xs + rng.uniform(0, spacing)) % spacing - spacing / 2
        gy = (ys + rng.uniform(0, spacing)) % spacing - spacing / 2
        mix = (np.hypot(gx, gy) < radius).astype(np.float32)
    elif kind == 2:  # bricks
        high, wide = rng.uniform(6.0, 18.0), rng.uniform(14.0, 40.0)
        row = np.floor(ys / high)
        offset = (row % 2) * wide / 2
        mortar = (ys % high < 1.5) | ((xs + offset) % wide < 1.5)
        mix = mortar.astype(np.float32)
    else:  # grain: noise blurred to any scale
        noise = rng.random(xs.shape).astype(np.float32)
        grain = np.asarray(cv2.GaussianBlur(noise, (0, 0), float(rng.uniform(0.6, 3.0))))
        mix = np.clip((grain - grain.mean()) * rng.uniform(3.0, 8.0) + 0.5, 0.0, 1.0)
    image = base + (other - base) * np.clip(mix, 0.0, 1.0)[..., np.newaxis]
    return np.asarray(np.clip(image, 0, 255), dtype=np.uint8)


def camera_effects(image: Frame, rng: Random) -> Frame:
    """Lighting, blur, sensor noise and JPEG, as a webcam adds them."""
    height, width = image.shape[:2]
    light = rng.uniform(0.55, 1.3)
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float32)
    angle = rng.uniform(0, 2 * np.pi)
    ramp = (np.cos(angle) * xs + np.sin(angle) * ys) / max(height, width)
    gain = light * (1.0 + rng.uniform(-0.3, 0.3) * ramp)
    lit = image.astype(np.float32) * gain[..., np.newaxis]
    if rng.random() < 0.5:
        sigma = rng.uniform(0.3, 1.4)
        lit = cv2.GaussianBlur(lit, (0, 0), sigma)
    lit += rng.normal(0.0, rng.uniform(0.0, 8.0), lit.shape).astype(np.float32)
    out = np.clip(lit, 0, 255).astype(np.uint8)
    if rng.random() < 0.5:
        ok, encoded = cv2.imencode(
            ".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, int(rng.integers(35, 95))]
        )
        if ok:
            out = cv2.imdecode(encoded, cv2.IMREAD_COLOR)
    return np.asarray(out, dtype=np.uint8)
