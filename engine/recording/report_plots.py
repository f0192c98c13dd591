"""The report's small line plots of the sensors over a session, as inline SVG."""

from __future__ import annotations

import html
from typing import Any


def plot(
    title: str,
    unit: str,
    series: list[tuple[str, str, list[tuple[float, float | None]]]],
    end_s: float,
) -> str:
    """A small line plot (SVG) of step-wise series over the session."""
    width, height, left, bottom = 680, 150, 48, 22
    values = [v for _, _, points in series for _, v in points if v is not None]
    if not values:
        return ""
    if not any(values):  # a flat line at 0 is an empty chart: say it
        return f'<p class="plot-none">{html.escape(title)}: none during the session.</p>'
    top = max(values) if max(values) > 0 else 1.0

    def x(t: float) -> float:
        return left + (width - left - 24) * (t / end_s if end_s else 0.0)

    def y(v: float) -> float:
        return 8 + (height - bottom - 8) * (1 - v / (top * 1.1))

    def text(at_x: float, at_y: float, words: str, anchor: str = "end", fill: str = "") -> str:
        colour = f' style="fill: {fill}"' if fill else ""
        return (
            f'<text x="{at_x:.1f}" y="{at_y:.1f}" class="tick" text-anchor="{anchor}"{colour}>'
            f"{html.escape(words)}</text>"
        )

    base = height - bottom
    parts = [
        f'<svg viewBox="0 0 {width} {height}" role="img" aria-label="{html.escape(title)}">',
        f'<text x="{left}" y="12" class="plot-title">{html.escape(title)} ({unit})</text>',
        f'<line x1="{left}" y1="{base}" x2="{width - 8}" y2="{base}" class="axis"/>',
        text(left - 4, y(top) + 4, f"{top:.3g}"),
        text(left - 4, base + 4, "0"),
    ]
    step = max(1.0, round(end_s / 8))
    t = 0.0
    while t <= end_s + 1e-9:
        parts.append(text(x(t), height - 6, f"{t:g} s", "middle"))
        t += step
    for index, (name, colour, points) in enumerate(series):
        dash = ' stroke-dasharray="5 3"' if index else ""
        for run in _runs(points, end_s):  # no reading (nothing in range): no line
            joined = " ".join(f"{x(at):.1f},{y(value):.1f}" for at, value in run)
            parts.append(f'<polyline fill="none" stroke="{colour}"{dash} points="{joined}"/>')
        parts.append(text(width - 10, 20 + 12 * index, name, "end", colour))
    parts.append("</svg>")
    return "".join(parts)


def _runs(
    points: list[tuple[float, float | None]], end_s: float
) -> list[list[tuple[float, float]]]:
    """Step-wise line pieces between the moments a value was absent."""
    runs: list[list[tuple[float, float]]] = []
    current: list[tuple[float, float]] = []
    for index, (at, value) in enumerate(points):
        until = points[index + 1][0] if index + 1 < len(points) else end_s
        if value is None:
            if current:
                runs.append(current)
            current = []
            continue
        current += [(at, value), (until, value)]
    if current:
        runs.append(current)
    return runs


def numbers(rows: list[tuple[float, Any]], scale: float = 1.0) -> list[tuple[float, float | None]]:
    """Readings as numbers (True is 1); None where the sensor saw nothing."""
    return [(at, float(v) * scale if isinstance(v, int | float) else None) for at, v in rows]


def per_session_plot(
    title: str,
    unit: str,
    series: list[tuple[str, str, list[float | None]]],
    labels: list[str],
) -> str:
    """A small plot (SVG) of one value per session, a point each joined by lines;
    ``labels`` names each session on the x axis; None: no value that session."""
    width, height, left, bottom = 680, 170, 48, 40
    values = [v for _, _, points in series for v in points if v is not None]
    if not values or not labels:
        return ""
    top = max(values) if max(values) > 0 else 1.0
    count = len(labels)

    def x(index: int) -> float:
        return left + (width - left - 24) * (index / (count - 1) if count > 1 else 0.5)

    def y(v: float) -> float:
        return 8 + (height - bottom - 8) * (1 - v / (top * 1.1))

    base = height - bottom
    parts = [
        f'<svg viewBox="0 0 {width} {height}" role="img" aria-label="{html.escape(title)}">',
        f'<text x="{left}" y="12" class="plot-title">{html.escape(title)} ({unit})</text>',
        f'<line x1="{left}" y1="{base}" x2="{width - 8}" y2="{base}" class="axis"/>',
        f'<text x="{left - 4}" y="{y(top) + 4:.1f}" class="tick" text-anchor="end">'
        f"{_tick(top)}</text>",
        f'<text x="{left - 4}" y="{base + 4}" class="tick" text-anchor="end">0</text>',
    ]
    parts.append(
        f'<text x="{width - 8}" y="{height - 4}" class="tick" text-anchor="end">'
        "session (# in the table)</text>"
    )
    every = max(1, count // 8)
    for index, label in enumerate(labels):
        if index % every == 0 or index == count - 1:
            parts.append(
                f'<text x="{x(index):.1f}" y="{base + 14}" class="tick" text-anchor="middle">'
                f"{html.escape(label)}</text>"
            )
    shapes = ("circle", "rect", "diamond")
    for number, (name, colour, points) in enumerate(series):
        dash = ' stroke-dasharray="5 3"' if number else ""
        shown = [(x(i), y(v)) for i, v in enumerate(points) if v is not None]
        if len(shown) > 1:
            joined = " ".join(f"{px:.1f},{py:.1f}" for px, py in shown)
            parts.append(f'<polyline fill="none" stroke="{colour}"{dash} points="{joined}"/>')
        for px, py in shown:  # a shape per series as well as a colour (colour-blind safe)
            parts.append(_marker(shapes[number % len(shapes)], px, py, colour))
        parts.append(
            f'<text x="{width - 10}" y="{20 + 12 * number}" class="tick" text-anchor="end" '
            f'style="fill: {colour}">{html.escape(name)}</text>'
        )
    parts.append("</svg>")
    return "".join(parts)


def _tick(value: float) -> str:
    """An axis's top value as a person reads it: 12, 3.5, 0.09."""
    return f"{value:.0f}" if value >= 10 else f"{value:.1f}" if value >= 1 else f"{value:.2f}"


def _marker(shape: str, px: float, py: float, colour: str) -> str:
    if shape == "circle":
        return f'<circle cx="{px:.1f}" cy="{py:.1f}" r="3" fill="{colour}"/>'
    if shape == "rect":
        return f'<rect x="{px - 3:.1f}" y="{py - 3:.1f}" width="6" height="6" fill="{colour}"/>'
    return (
        f'<polygon points="{px:.1f},{py - 4:.1f} {px + 4:.1f},{py:.1f} {px:.1f},{py + 4:.1f} '
        f'{px - 4:.1f},{py:.1f}" fill="{colour}"/>'
    )
