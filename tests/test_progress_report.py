"""A person's progress over sessions as a supervisor reads it: every session a point of the
trend, rates per minute so a short and a long session compare, simulated sessions marked,
and plots whose labels stay on the page when printed on A4."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

from engine.recording.progress import SessionSummary, progress_html

DAY_S = 86_400.0


def session(n: int, length_s: float, did: int, *, simulated: bool = False) -> SessionSummary:
    return SessionSummary(
        Path(f"s{n}.vest"),
        1_795_000_000.0 + n * DAY_S,
        length_s,
        did,
        tuple(0.5 for _ in range(did)),
        0,
        0,
        {"hug": (0.5,) * did},
        simulated,
    )


def test_sessions_of_any_length_compare_by_their_rate_per_minute() -> None:
    page = progress_html("kid-17", [session(1, 20.0, 4), session(2, 88.0, 8)], [])
    assert "Things done per minute, session by session: 12.0, 5.5." in page
    assert "<td class='num'>12.0</td>" in page and "<td class='num'>5.5</td>" in page


def test_a_simulated_session_counted_on_request_is_marked() -> None:
    page = progress_html("kid-17", [session(1, 60.0, 3, simulated=True)], [])
    assert " (simulated)</td>" in page


def test_the_plots_labels_stay_inside_the_page() -> None:
    sessions = [session(n, 60.0, n) for n in range(1, 13)]
    page = progress_html("kid-17", sessions, [])
    for svg in re.findall(r"<svg viewBox=\"0 0 (\d+) \d+\".*?</svg>", page, re.S):
        assert int(svg) == 680
    for x, anchor, text in re.findall(
        r'<text x="([\d.]+)" y="[\d.]+" class="tick" text-anchor="(\w+)"[^>]*>([^<]*)</text>', page
    ):
        half = len(text) * 3.5 if anchor == "middle" else 0  # about 7 px a character
        left = float(x) - (len(text) * 7 if anchor == "end" else half)
        right = float(x) + (len(text) * 7 if anchor == "start" else half)
        assert left >= 0 and right <= 680, (x, anchor, text)


def test_one_session_is_told_as_one_not_as_a_first_and_a_latest() -> None:
    page = progress_html("kid-17", [session(1, 60.0, 3)], [])
    assert '<p class="meta">1 session from ' in page
    assert "In this session the person did 3 things and the robot answered 3." in page
    assert "In the first session" not in page


def test_speaking_over_the_robot_counts_each_time_and_those_it_could_not_hear() -> None:
    spoke = dataclasses.replace(session(1, 60.0, 3), spoken_over=2, not_listened=1)
    page = progress_html("kid-17", [spoke], [])
    assert "<td class='num'>3 (1 not heard)</td></tr>" in page
    assert "Spoke over the robot: times the person spoke while the robot was talking" in page


def test_an_axis_s_top_reads_as_a_person_reads_a_number() -> None:
    quick = dataclasses.replace(session(1, 60.0, 2), answer_s=(0.0884, 0.0884))
    page = progress_html("kid-17", [quick], [])
    assert ">0.09</text>" in page and "0.0884" not in page


def test_a_squeeze_counted_toward_the_next_one_s_answer_is_not_called_answered() -> None:
    twice = dataclasses.replace(session(1, 60.0, 2), answer_s=(0.4,), counted=1)
    page = progress_html("kid-17", [twice], [])
    assert "did 2 things and the robot answered 1, and counted 1 toward an answer" in page
    assert "<td class='num'>1 (+1 counted)</td>" in page
