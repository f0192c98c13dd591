"""The scheduler's thread hands items to a worker and never waits: a worker that falls
behind costs dropped items, counted; one that stops (a full disk) stops taking, and
closing never hangs."""

from __future__ import annotations

import threading

from engine.session.handoff import Handoff


def test_every_item_is_handled_in_order_and_closing_waits_for_the_last() -> None:
    handled: list[int] = []
    handoff: Handoff[int] = Handoff(
        "test", lambda batch: handled.extend(batch) or True, capacity=100
    )
    handoff.start()
    for number in range(50):
        handoff.put(number)
    handoff.close()
    assert handled == list(range(50)) and handoff.dropped == 0


def test_a_worker_that_falls_behind_costs_dropped_items_never_a_wait() -> None:
    taken, busy, handled = threading.Event(), threading.Event(), []

    def slow(batch: list[int]) -> bool:
        taken.set()
        busy.wait()  # the disk is slow until the test lets it go
        handled.extend(batch)
        return True

    handoff: Handoff[int] = Handoff("test", slow, capacity=3)
    handoff.start()
    handoff.put(0)
    taken.wait()  # the worker holds it, and waits on the disk
    for number in range(1, 10):
        handoff.put(number)
    assert handoff.dropped == 6  # three waiting, the rest dropped
    busy.set()
    handoff.close()
    assert handled == [0, 1, 2, 3]


def test_a_worker_that_stops_takes_nothing_more_and_closing_returns() -> None:
    handled: list[list[int]] = []

    def refuses(batch: list[int]) -> bool:
        handled.append(batch)
        return False

    handoff: Handoff[int] = Handoff("test", refuses, capacity=2, batch=1)
    handoff.start()
    for number in range(5):
        handoff.put(number)
    handoff.close()
    assert handled[0] == [0] and len(handled) == 1
