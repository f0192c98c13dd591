"""Procedurally drawn hands showing 0..5 fingers: the data the shipped model learns from.

No package ships real finger-count pictures, so the project draws its own and publishes
how (this module, the seeds and the training command in docs/vision-model-card.md), so
anyone can rebuild the model and check its accuracy. A hand is a palm, a forearm leaving
the window at the bottom, and five digits each extended or folded, in any combination
that shows the asked count; pose, scale, rotation, mirroring, skin tone, lighting,
clutter, blur, noise and JPEG vary with the seed.

The shipped model learns from two styles, ``studio`` (round-ended fingers, an elliptic
palm, plain, graded or cluttered rooms) and ``wallpaper`` (the same hands before busy
patterned walls: plaids, dots, bricks, grain). A third, ``variant``, is drawn by other
code and never trained on, so it checks what the model learnt: tapered fingers, a
polygonal palm, a sleeve, striped, checked or smoothly textured backgrounds. Everything is drawn
in the 128 x 128 px window the paper crops; :func:`render_frame` places it in a full
640 x 360 frame for the simulated camera.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path

import cv2
import numpy as np

from engine.errors import ConfigError
from engine.media.images import Frame
from engine.vision.preprocess import SIDE_PX
from engine.vision_training.synthetic_rooms import background, camera_effects

STYLES = ("studio", "wallpaper", "varied", "variant")
TRAINING_STYLES = ("studio", "wallpaper")
"""Styles whose hands :func:`draw_hand` draws alike (round-ended fingers, an elliptic
palm); ``varied`` hands come from :func:`draw_varied_hand`; all three are trained on."""
"""The styles the shipped model learns from: their hands are drawn alike (round-ended
fingers, an elliptic palm); only their backgrounds differ."""
NO_HAND = "none"
"""The folder name of frames with no hand in them (trained towards "not sure")."""
Random = np.random.Generator
Point = tuple[float, float]

# The digits of a right hand seen from the palm side, from the thumb: where each sits on
# the palm (fraction of the palm's half-width, fraction of its half-height, negative is
# up), its direction (degrees from straight up, positive to the right of the picture),
# its length and width (fractions of the palm's half-height).
DIGITS = (
    ("thumb", -1.0, 0.15, -52.0, 0.95, 0.40),
    ("index", -0.62, -0.85, -9.0, 1.35, 0.34),
    ("middle", -0.18, -0.97, -1.0, 1.48, 0.35),
    ("ring", 0.27, -0.93, 7.0, 1.36, 0.33),
    ("little", 0.68, -0.78, 17.0, 1.08, 0.29),
)
SKIN_TONES_BGR = (
    (197, 224, 255),
    (170, 205, 240),
    (140, 180, 225),
    (105, 150, 200),
    (80, 120, 170),
    (60, 90, 140),
    (45, 65, 105),
    (35, 50, 80),
)


@dataclass(frozen=True)
class HandPose:
    """Where and how a hand is drawn in the window: palm centre (px), palm half-height
    (px), rotation (degrees, clockwise), mirrored (a left hand), which digits are up."""

    centre: Point
    palm_px: float
    angle_deg: float
    mirrored: bool
    extended: tuple[bool, ...]

    @property
    def fingers(self) -> int:
        return sum(self.extended)


def extended_digits(fingers: int, rng: Random) -> tuple[bool, ...]:
    """Which of the five digits are up for a hand showing ``fingers``: any combination,
    with the common ones (the first fingers, then the thumb) more often."""
    if not 0 <= fingers <= 5:
        raise ValueError(f"a hand shows 0..5 fingers, not {fingers}")
    if fingers in (0, 5) or rng.random() < 0.5:
        common = [1, 2, 3, 4, 0][:fingers] if rng.random() < 0.6 else [0, 1, 2, 3, 4][:fingers]
        chosen = set(common)
    else:
        options = list(combinations(range(5), fingers))
        chosen = set(options[int(rng.integers(len(options)))])
    return tuple(digit in chosen for digit in range(5))


def random_pose(fingers: int, rng: Random, side_px: int = SIDE_PX) -> HandPose:
    """A pose that keeps the hand mostly inside the central 128 x 128 px of a picture
    ``side_px`` square (the hand keeps its size whatever the picture's)."""
    palm = float(rng.uniform(19.0, 27.0))
    centre = (
        side_px / 2 + float(rng.normal(0.0, 7.0)),
        side_px / 2 + 15.0 + float(rng.normal(0.0, 6.0)),
    )
    return HandPose(
        centre=centre,
        palm_px=palm,
        angle_deg=float(rng.normal(0.0, 13.0)),
        mirrored=bool(rng.random() < 0.5),
        extended=extended_digits(fingers, rng),
    )


def _place(pose: HandPose, x: float, y: float) -> Point:
    """A point given in palm units (x right, y down, palm half-height 1) in window px."""
    if pose.mirrored:
        x = -x
    angle = math.radians(pose.angle_deg)
    cos, sin = math.cos(angle), math.sin(angle)
    return (
        pose.centre[0] + pose.palm_px * (x * cos - y * sin),
        pose.centre[1] + pose.palm_px * (x * sin + y * cos),
    )


def _digit_line(
    pose: HandPose, digit: int, length_scale: float, rng: Random
) -> tuple[Point, Point, float]:
    """A digit's base and tip (window px) and its width (px)."""
    _, bx, by, direction, length, width = DIGITS[digit]
    bx, by = bx * 0.78, by * 0.95
    direction += float(rng.normal(0.0, 5.0))
    length *= length_scale * float(rng.uniform(0.9, 1.1))
    tip_x = bx + length * math.sin(math.radians(direction))
    tip_y = by - length * math.cos(math.radians(direction))
    return _place(pose, bx, by), _place(pose, tip_x, tip_y), width * pose.palm_px


def _shade(colour: Sequence[int], factor: float) -> tuple[int, int, int]:
    b, g, r = (int(np.clip(c * factor, 0, 255)) for c in colour)
    return b, g, r


def _px(point: Point) -> tuple[int, int]:
    return round(point[0] * 16), round(point[1] * 16)


def _capsule(image: Frame, start: Point, end: Point, width: float, colour: Sequence[int]) -> None:
    """A round-ended stroke (the studio style's finger)."""
    cv2.line(image, _px(start), _px(end), _shade(colour, 1.0), max(2, round(width)), cv2.LINE_AA, 4)


def _tapered(image: Frame, start: Point, end: Point, width: float, colour: Sequence[int]) -> None:
    """A finger narrowing to a rounded tip (the variant style's finger)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    norm = math.hypot(dx, dy) or 1.0
    nx, ny = -dy / norm, dx / norm
    base, tip = width / 2, width * 0.3
    polygon = np.array(
        [
            (start[0] + nx * base, start[1] + ny * base),
            (end[0] + nx * tip, end[1] + ny * tip),
            (end[0] - nx * tip, end[1] - ny * tip),
            (start[0] - nx * base, start[1] - ny * base),
        ]
    )
    cv2.fillPoly(
        image, [np.round(polygon * 16).astype(np.int32)], _shade(colour, 1.0), cv2.LINE_AA, 4
    )
    cv2.circle(image, _px(end), max(1, round(tip * 16)), _shade(colour, 1.0), -1, cv2.LINE_AA, 4)


def _luma(colour: Sequence[float]) -> float:
    b, g, r = colour
    return 0.114 * b + 0.587 * g + 0.299 * r


def _skin_tone(image: Frame, pose: HandPose, rng: Random) -> tuple[int, int, int]:
    """A skin tone that stands out from the background around the hand by at least 30
    grey levels when one does (a hand the camera cannot tell from the wall teaches the
    network nothing but guessing)."""
    x, y = round(pose.centre[0]), round(pose.centre[1])
    reach = round(pose.palm_px * 2)
    around = image[max(0, y - reach) : y + reach, max(0, x - reach) : x + reach]
    background = _luma(around.reshape(-1, 3).mean(axis=0)) if around.size else 128.0
    standing_out = [t for t in SKIN_TONES_BGR if abs(_luma(t) - background) >= 30]
    tones = standing_out or list(SKIN_TONES_BGR)
    return tones[int(rng.integers(len(tones)))]


def draw_hand(image: Frame, pose: HandPose, rng: Random, *, style: str) -> None:
    """The hand in ``pose`` drawn onto ``image`` (BGR, in place)."""
    skin = np.array(_skin_tone(image, pose, rng), dtype=float)
    skin = skin * rng.uniform(0.85, 1.15, size=3)
    colour = tuple(int(c) for c in np.clip(skin, 0, 255))
    outline = rng.random() < 0.35
    dark = _shade(colour, float(rng.uniform(0.55, 0.8)))
    drawn_as_studio = style in TRAINING_STYLES
    finger = _capsule if drawn_as_studio else _tapered

    # The forearm (or, in the variant style, a sleeve) leaves the window at the bottom.
    forearm = [
        _place(pose, -0.8, 0.6),
        _place(pose, 0.8, 0.6),
        _place(pose, 1.0, 4.5),
        _place(pose, -1.0, 4.5),
    ]
    arm_colour = (
        colour
        if drawn_as_studio or rng.random() < 0.4
        else tuple(int(c) for c in rng.integers(0, 256, 3))
    )
    cv2.fillPoly(
        image, [np.round(np.array(forearm) * 16).astype(np.int32)], arm_colour, cv2.LINE_AA, 4
    )

    # Folded digits first (the knuckles show above the palm), the palm, then the digits up.
    for digit in range(5):
        if not pose.extended[digit]:
            scale = 0.35 if digit == 0 else float(rng.uniform(0.15, 0.3))
            base, tip, width = _digit_line(pose, digit, scale, rng)
            finger(image, base, tip, width * 1.05, _shade(colour, 0.93))
    if drawn_as_studio:
        axes = (pose.palm_px * 0.95, pose.palm_px * 1.05)
        cv2.ellipse(
            image,
            _px(pose.centre),
            (round(axes[0] * 16), round(axes[1] * 16)),
            pose.angle_deg,
            0,
            360,
            colour,
            -1,
            cv2.LINE_AA,
            4,
        )
    else:
        corners = [(-0.9, -0.95), (0.85, -0.85), (1.0, 0.4), (0.7, 1.0), (-0.7, 1.0), (-1.0, 0.3)]
        polygon = np.array([_place(pose, x, y) for x, y in corners])
        cv2.fillPoly(image, [np.round(polygon * 16).astype(np.int32)], colour, cv2.LINE_AA, 4)
    if not pose.extended[0]:
        # A folded thumb lies across the palm.
        start, end = _place(pose, -0.9, 0.3), _place(pose, 0.1, -0.1)
        finger(image, start, end, pose.palm_px * 0.38, _shade(colour, 0.9))
    for digit in range(5):
        if pose.extended[digit]:
            base, tip, width = _digit_line(pose, digit, 1.0, rng)
            if outline:
                finger(image, base, tip, width + 2.0, dark)
            finger(image, base, tip, width, colour)


def draw_varied_hand(image: Frame, pose: HandPose, rng: Random) -> None:
    """A hand of the varied style onto ``image``: a lumpy palm, jointed fingers narrowing
    by a random amount, a cuff or a sleeve now and then (shapes the studio hands lack)."""
    colour = tuple(
        int(c)
        for c in np.clip(
            np.array(_skin_tone(image, pose, rng)) * rng.uniform(0.85, 1.15, 3), 0, 255
        )
    )
    cloth = tuple(int(c) for c in rng.integers(0, 256, 3))
    clothed = rng.random()  # < 0.3: a sleeve up to the palm; < 0.55: a cuff at the wrist
    arm_top = 0.6 if clothed >= 0.3 else 0.75
    forearm = [(-0.8, arm_top), (0.8, arm_top), (1.05, 4.5), (-1.05, 4.5)]
    arm = np.array([_place(pose, x, y) for x, y in forearm])
    cv2.fillPoly(
        image,
        [np.round(arm * 16).astype(np.int32)],
        cloth if clothed < 0.3 else colour,
        cv2.LINE_AA,
        4,
    )
    if 0.3 <= clothed < 0.55:
        cuff = np.array(
            [_place(pose, x, y) for x, y in [(-0.9, 1.6), (0.9, 1.6), (0.95, 2.2), (-0.95, 2.2)]]
        )
        cv2.fillPoly(image, [np.round(cuff * 16).astype(np.int32)], cloth, cv2.LINE_AA, 4)

    taper = float(rng.uniform(0.5, 1.0))  # tip width / base width
    aspect = float(rng.uniform(0.85, 1.15))

    def jointed(digit: int, length_scale: float, shade: float) -> None:
        base, tip, width = _digit_line(pose, digit, length_scale, rng)
        bend = float(rng.normal(0.0, 0.06))
        points = [base]
        for step in (1, 2, 3):
            share = step / 3
            x = base[0] + (tip[0] - base[0]) * share + bend * pose.palm_px * step * (step - 1) / 6
            y = base[1] + (tip[1] - base[1]) * share
            points.append((x, y))
        for index in range(3):
            thick = width * (1.0 - (1.0 - taper) * (index + 0.5) / 3)
            _capsule(image, points[index], points[index + 1], thick, _shade(colour, shade))

    for digit in range(5):
        if not pose.extended[digit]:
            jointed(digit, 0.35 if digit == 0 else float(rng.uniform(0.15, 0.3)), 0.93)
    angles = np.linspace(0, 2 * np.pi, 18, endpoint=False)
    bumps = 1.0 + rng.normal(0.0, 0.06, 18)
    palm = np.array(
        [
            _place(pose, 0.95 * aspect * r * np.cos(a), 1.05 / aspect * r * np.sin(a))
            for a, r in zip(angles, bumps, strict=True)
        ]
    )
    cv2.fillPoly(image, [np.round(palm * 16).astype(np.int32)], colour, cv2.LINE_AA, 4)
    if not pose.extended[0]:
        _capsule(
            image,
            _place(pose, -0.9, 0.3),
            _place(pose, 0.1, -0.1),
            pose.palm_px * 0.38,
            _shade(colour, 0.9),
        )
    for digit in range(5):
        if pose.extended[digit]:
            jointed(digit, 1.0, 1.0)


def _draw(image: Frame, pose: HandPose, rng: Random, style: str) -> None:
    if style == "varied":
        draw_varied_hand(image, pose, rng)
    else:
        draw_hand(image, pose, rng, style=style)


def _check_style(style: str) -> None:
    if style not in STYLES:
        raise ValueError(f"style must be one of {', '.join(STYLES)}, not {style!r}")


def render_window(
    fingers: int | None, rng: Random, *, style: str = "studio", side_px: int = SIDE_PX
) -> Frame:
    """A window-sized (``side_px`` square) BGR picture of a hand showing ``fingers``, or
    of no hand when ``fingers`` is None."""
    _check_style(style)
    image = background(side_px, side_px, rng, style)
    if fingers is not None:
        _draw(image, random_pose(fingers, rng, side_px), rng, style)
    return camera_effects(image, rng)


def render_frame(
    fingers: int | None,
    rng: Random,
    *,
    style: str = "studio",
    width_px: int = 640,
    height_px: int = 360,
    window: tuple[int, int] | None = None,
) -> Frame:
    """A full camera frame with the hand (or no hand) in the crop window, whose top-left
    corner is ``window`` (None: centred), and the rest of the frame background."""
    _check_style(style)
    x, y = window if window is not None else ((width_px - SIDE_PX) // 2, (height_px - SIDE_PX) // 2)
    frame = background(height_px, width_px, rng, style)
    if fingers is not None:
        window_view = frame[y : y + SIDE_PX, x : x + SIDE_PX]
        _draw(window_view, random_pose(fingers, rng), rng, style)
    return camera_effects(frame, rng)


def write_dataset(
    out: Path, count: int, seed: int, *, style: str = "studio", empty_share: float = 0.1
) -> int:
    """``count`` labelled pictures written as ``out/<fingers>/<style>-<seed>-<i>.png`` (and
    ``out/none/`` for frames with no hand, ``empty_share`` of them), 16 px wider than the
    window on each side so training can shift the crop. Returns how many were written."""
    _check_style(style)
    rng = np.random.default_rng(seed)
    side = SIDE_PX + 32
    for index in range(count):
        fingers: int | None = None if rng.random() < empty_share else int(index % 6)
        folder = out / (NO_HAND if fingers is None else str(fingers))
        folder.mkdir(parents=True, exist_ok=True)
        image = render_window(fingers, rng, style=style, side_px=side)
        path = folder / f"{style}-{seed}-{index:06d}.png"
        if not cv2.imwrite(str(path), image):
            raise ConfigError(f"{path}: cannot be written")
    return count
