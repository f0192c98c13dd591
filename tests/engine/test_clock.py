"""Clocks: a worker thread waits on the injected clock, so a virtual clock drives it too."""

from __future__ import annotations

import threading

import pytest

from engine.clock import RealClock, VirtualClock


def test_a_wait_on_a_set_event_returns_at_once() -> None:
    clock = VirtualClock()
    stop = clock.event()
    stop.set()
    assert clock.wait(stop, 10.0) is True
    assert clock.now() == 0.0


def test_a_zero_wait_reports_the_event_without_blocking() -> None:
    clock = VirtualClock()
    assert clock.wait(clock.event(), 0.0) is False


def test_a_worker_waiting_on_a_virtual_clock_wakes_when_time_is_advanced() -> None:
    clock = VirtualClock()
    stop = clock.event()
    results: list[bool] = []
    worker = threading.Thread(target=lambda: results.append(clock.wait(stop, 1.0)))
    worker.start()
    assert clock.until_waiting(1)
    clock.advance(0.5)  # not yet: the worker's timeout is one virtual second
    clock.advance(0.5)
    worker.join(timeout=5)
    assert results == [False]  # timed out on virtual time, never on the wall clock


def test_setting_the_event_wakes_a_worker_before_its_timeout() -> None:
    clock = VirtualClock()
    stop = clock.event()
    results: list[bool] = []
    worker = threading.Thread(target=lambda: results.append(clock.wait(stop, 3600.0)))
    worker.start()
    assert clock.until_waiting(1)
    stop.set()
    worker.join(timeout=5)
    assert results == [True]
    assert clock.now() == 0.0


def test_a_cleared_event_can_be_waited_for_again() -> None:
    clock = VirtualClock()
    stop = clock.event()
    stop.set()
    stop.clear()
    assert clock.wait(stop, 0.0) is False


def test_a_real_sleep_until_ends_early_when_its_stop_event_is_set() -> None:
    clock = RealClock()
    stop = clock.event()
    stop.set()  # the scheduler was asked to stop: its wait for the next deadline ends at once
    assert clock.sleep_until(clock.now() + 3600.0, stop) is True
    assert clock.sleep_until(clock.now() - 1.0) is False  # a deadline passed returns at once


def test_a_virtual_sleep_until_jumps_unless_stopped() -> None:
    clock = VirtualClock()
    stop = clock.event()
    assert clock.sleep_until(5.0, stop) is False
    assert clock.now() == 5.0
    stop.set()
    assert clock.sleep_until(9.0, stop) is True
    assert clock.now() == 5.0


def test_an_event_of_another_clock_is_refused() -> None:
    with pytest.raises(ValueError, match=r"clock\.event\(\)"):
        VirtualClock().wait(RealClock().event(), 1.0)
