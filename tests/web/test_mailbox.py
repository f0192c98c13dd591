"""A page's mailbox: the robot gives without waiting, the page's stream takes on the event
loop, and a page that falls behind is told so instead of slowing anyone."""

from __future__ import annotations

import asyncio
import threading

from engine.clock import VirtualClock
from engine.web.mailbox import Mailbox, Taken


def test_what_was_given_is_taken_in_order_at_once() -> None:
    mailbox: Mailbox[int] = Mailbox(VirtualClock(), capacity=10)
    for change in (1, 2, 3):
        mailbox.give(change)
    assert asyncio.run(mailbox.take(15.0)) == Taken([1, 2, 3], overflowed=False)


def test_a_page_that_fell_behind_keeps_the_newest_and_hears_it_lost_some() -> None:
    mailbox: Mailbox[int] = Mailbox(VirtualClock(), capacity=3)
    for change in range(10):
        mailbox.give(change)  # never waits, however far behind the page is
    assert asyncio.run(mailbox.take(15.0)) == Taken([7, 8, 9], overflowed=True)
    mailbox.give(10)
    assert asyncio.run(mailbox.take(15.0)) == Taken([10], overflowed=False)


def test_a_waiting_page_wakes_when_the_robot_gives_from_its_own_thread() -> None:
    clock = VirtualClock()
    mailbox: Mailbox[str] = Mailbox(clock, capacity=10)

    def robot() -> None:
        assert clock.until_waiting(1)  # the page waits (holding no thread)
        mailbox.give("hug")

    giver = threading.Thread(target=robot)
    giver.start()
    taken = asyncio.run(mailbox.take(15.0))
    giver.join()
    assert taken == Taken(["hug"], overflowed=False)  # the clock never moved


def test_nothing_for_a_while_is_an_empty_take_and_a_closed_mailbox_ends_the_stream() -> None:
    clock = VirtualClock()
    mailbox: Mailbox[str] = Mailbox(clock, capacity=10)

    def time_passes_then_the_session_ends() -> None:
        assert clock.until_waiting(1)
        clock.advance(15.0)  # the page's keep-alive is due
        assert clock.until_waiting(1, entered=2)
        mailbox.give("end")
        mailbox.close()

    async def page() -> list[Taken[str] | None]:
        return [await mailbox.take(15.0), await mailbox.take(15.0), await mailbox.take(15.0)]

    other = threading.Thread(target=time_passes_then_the_session_ends)
    other.start()
    taken = asyncio.run(page())
    other.join()
    assert taken == [Taken([], overflowed=False), Taken(["end"], overflowed=False), None]
    mailbox.give("late")  # nothing is taken after the end
    assert asyncio.run(mailbox.take(15.0)) is None
