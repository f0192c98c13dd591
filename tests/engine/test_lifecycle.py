"""A robot's parts start in order and stop in reverse, every one of them, whatever fails."""

from __future__ import annotations

import pytest

from engine.runtime.lifecycle import Lifecycle


def parts(lifecycle: Lifecycle, said: list[str], *names: str) -> None:
    for name in names:
        lifecycle.add(
            name,
            start=lambda name=name: said.append(f"start {name}"),
            stop=lambda name=name: said.append(f"stop {name}"),
        )


def test_parts_start_in_order_and_stop_in_reverse_after_what_they_hold() -> None:
    said: list[str] = []
    lifecycle = Lifecycle()
    lifecycle.add("buses", stop=lambda: said.append("close buses"))  # held from the start
    parts(lifecycle, said, "view", "pollers", "cloud link")
    lifecycle.start()
    lifecycle.stop()
    assert said == [
        "start view",
        "start pollers",
        "start cloud link",
        "stop cloud link",
        "stop pollers",
        "stop view",
        "close buses",
    ]
    lifecycle.stop()  # stopping twice stops nothing twice
    assert len(said) == 7


def test_a_part_that_fails_to_start_stops_those_before_it_and_is_raised() -> None:
    said: list[str] = []
    lifecycle = Lifecycle()
    lifecycle.add("buses", stop=lambda: said.append("close buses"))
    parts(lifecycle, said, "view")

    def port_taken() -> None:
        raise OSError("port taken")

    lifecycle.add("server", start=port_taken, stop=lambda: said.append("stop server"))
    parts(lifecycle, said, "never")
    with pytest.raises(OSError, match="port taken"):
        lifecycle.start()
    assert said == ["start view", "stop view", "close buses"]


def test_a_stop_that_fails_does_not_keep_the_others_from_stopping() -> None:
    said: list[str] = []
    lifecycle = Lifecycle()
    lifecycle.add("buses", stop=lambda: said.append("close buses"))

    def stuck() -> None:
        raise RuntimeError("the camera is stuck")

    lifecycle.add("camera", start=lambda: None, stop=stuck)
    parts(lifecycle, said, "link")
    lifecycle.start()
    with pytest.raises(RuntimeError, match="stuck"):
        lifecycle.stop()
    assert said == ["start link", "stop link", "close buses"]
